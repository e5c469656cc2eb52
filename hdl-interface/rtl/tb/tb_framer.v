// sc_framer against the Rust framer: for each packet of the vector file (+vectors=PATH,
// written by tests/tests/rtl_framer.rs from `Framer::send`), the packet's bytes go in with
// random gaps while OUT is read with random stalls; every byte out must be the expected link
// frame's, up to and including its delimiter. Record layout, text, one packet per record:
//   FEC LEN  LEN packet bytes (hex)  FLEN  FLEN frame bytes (hex)
// Prints PASS tb_framer or FAIL lines.
`timescale 1ns / 1ps
`default_nettype none

module tb_framer;
    reg        clk = 1'b0;
    always #5 clk = ~clk;
    reg        rst = 1'b1;
    reg        fec = 1'b0;
    reg  [7:0] in_data = 8'd0;
    reg        in_valid = 1'b0, in_last = 1'b0;
    wire       in_ready;
    wire [7:0] out_data;
    wire       out_valid;
    reg        out_ready = 1'b0;

    sc_framer dut (
        .clk(clk), .rst(rst), .fec(fec),
        .in_data(in_data), .in_valid(in_valid), .in_last(in_last), .in_ready(in_ready),
        .out_data(out_data), .out_valid(out_valid), .out_ready(out_ready)
    );

    reg  [7:0] pkt [0:4095];
    reg  [7:0] frame [0:4095];
    integer    fd, fec_i, len, flen, i, got, failures, packets, seed, bytes_out, r;
    reg [1023:0] path;

    task feed;
        integer at;
        reg taken;
        begin
            at = 0;
            while (at < len) begin
                @(negedge clk);
                in_valid = ($random(seed) % 4) != 0;
                in_data = pkt[at];
                in_last = at == len - 1;
                fec = fec_i != 0;
                taken = in_valid && in_ready;
                @(posedge clk);
                if (taken) at = at + 1;
            end
            @(negedge clk);
            in_valid = 1'b0;
            in_last = 1'b0;
        end
    endtask

    task collect;
        reg taken;
        reg [7:0] byte_out;
        reg done;
        begin
            got = 0;
            done = 1'b0;
            while (!done) begin
                @(negedge clk);
                out_ready = ($random(seed) % 3) != 0;
                taken = out_valid && out_ready;
                byte_out = out_data;
                @(posedge clk);
                if (taken) begin
                    if (got >= flen || byte_out !== frame[got]) begin
                        if (failures < 10)
                            $display("FAIL packet %0d byte %0d: got %h, want %h (frame of %0d)",
                                     packets, got, byte_out, got < flen ? frame[got] : 8'hxx,
                                     flen);
                        failures = failures + 1;
                        done = 1'b1;
                    end
                    got = got + 1;
                    bytes_out = bytes_out + 1;
                    if (byte_out == 8'd0) done = 1'b1;
                end
            end
            if (got != flen && failures == 0) begin
                $display("FAIL packet %0d: %0d bytes out, want %0d", packets, got, flen);
                failures = failures + 1;
            end
        end
    endtask

    initial begin
        failures = 0;
        packets = 0;
        bytes_out = 0;
        seed = 7;
        if (!$value$plusargs("vectors=%s", path)) begin
            $display("FAIL: no +vectors=PATH");
            $finish;
        end
        fd = $fopen(path, "r");
        if (fd == 0) begin
            $display("FAIL: cannot open the vectors");
            $finish;
        end
        repeat (2) @(negedge clk);
        rst = 1'b0;
        while (failures == 0 && $fscanf(fd, "%d %d", fec_i, len) == 2) begin
            for (i = 0; i < len; i = i + 1) r = $fscanf(fd, "%h", pkt[i]);
            r = $fscanf(fd, "%d", flen);
            for (i = 0; i < flen; i = i + 1) r = $fscanf(fd, "%h", frame[i]);
            fork
                feed;
                collect;
            join
            packets = packets + 1;
        end
        $fclose(fd);
        if (failures == 0 && packets > 0)
            $display("PASS tb_framer: %0d packets, %0d bytes out", packets, bytes_out);
        else
            $display("FAIL tb_framer: %0d failures in %0d packets", failures, packets);
        $finish;
    end
endmodule

`default_nettype wire
