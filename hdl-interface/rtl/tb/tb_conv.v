// Self-checking testbench of sc_row_conv -> sc_col_conv (kernel G0) against a direct
// reference: the separable convolution with replicated borders computed here with
// multiplications on whole frames, `(sum tap*v + 512) >> 10` after each pass (convolver.rs).
// Frames: flat (unity DC gain: output = input), single impulses of 1024 (output = the
// product of taps, rounded), impulses at the corners (border replication) and pseudo-random
// images; sizes from 3x3 up to the line length. Each frame runs twice: with the enable high on
// every clock and an input on every enabled clock, where output n must leave exactly at
// enabled clock n + gaussian_latency(w) = n + 2w + 4; and with random enable and input gaps,
// where the outputs must come in raster order, all w*h of them, none more.
// Prints PASS tb_conv or the first mismatches and FAIL tb_conv.
`default_nettype none

module tb_conv;
    localparam W = 16;
    localparam [49:0] TAPS = {10'd35, 10'd244, 10'd466, 10'd244, 10'd35};

    reg         clk = 1'b0, start = 1'b0, en = 1'b0, in_valid = 1'b0;
    reg  [15:0] in_data = 16'd0, width = 16'd0, height = 16'd0;
    reg  [31:0] total = 32'd0;
    wire        rv, cv;
    wire [15:0] rd, cd;

    sc_row_conv #(.TAPS(TAPS)) u_row (
        .clk(clk), .start(start), .en(en), .width(width), .total(total),
        .in_valid(in_valid), .in_data(in_data), .out_valid(rv), .out_data(rd));
    sc_col_conv #(.W(W), .TAPS(TAPS)) u_col (
        .clk(clk), .start(start), .en(en), .width(width), .height(height), .total(total),
        .in_valid(rv), .in_data(rd), .out_valid(cv), .out_data(cd));

    reg [15:0] img [0:W*W-1];
    reg [15:0] rowref [0:W*W-1];
    reg [15:0] ref [0:W*W-1];
    integer errors = 0;
    reg [31:0] lfsr = 32'h1234_5678;

    function integer clampi;
        input integer v, mx;
        clampi = (v < 0) ? 0 : (v > mx) ? mx : v;
    endfunction

    function integer tap;
        input integer k;
        tap = TAPS[k*10 +: 10];
    endfunction

    task step_lfsr;
        lfsr = {lfsr[30:0], lfsr[31] ^ lfsr[21] ^ lfsr[1] ^ lfsr[0]};
    endtask

    task reference;
        input integer w, h;
        integer x, y, k, acc;
        begin
            for (y = 0; y < h; y = y + 1)
                for (x = 0; x < w; x = x + 1) begin
                    acc = 512;
                    for (k = 0; k < 5; k = k + 1) acc = acc + tap(k) * img[y*w + clampi(x+k-2, w-1)];
                    rowref[y*w + x] = acc >> 10;
                end
            for (y = 0; y < h; y = y + 1)
                for (x = 0; x < w; x = x + 1) begin
                    acc = 512;
                    for (k = 0; k < 5; k = k + 1) acc = acc + tap(k) * rowref[clampi(y+k-2, h-1)*w + x];
                    ref[y*w + x] = acc >> 10;
                end
        end
    endtask

    task tick;
        begin
            #1 clk = 1'b1;
            #1 clk = 1'b0;
        end
    endtask

    // Runs one frame; gaps = 0: en always high and an input on every enabled clock.
    task run;
        input integer w, h, gaps;
        input [8*24-1:0] name;
        integer fed, got, clk_en, guard;
        begin
            reference(w, h);
            width = w; height = h; total = w * h;
            start = 1'b1; en = 1'b0; in_valid = 1'b0;
            tick;
            start = 1'b0;
            fed = 0; got = 0; clk_en = 0; guard = 0;
            while (got < w * h && guard < 100000) begin
                step_lfsr;
                en = gaps ? lfsr[0] | lfsr[1] : 1'b1;
                in_valid = (fed < w * h) && (gaps ? lfsr[2] | lfsr[3] : 1'b1);
                in_data = (fed < w * h) ? img[fed] : 16'hxxxx;
                #1;
                if (en && cv) begin
                    if (cd !== ref[got] || (!gaps && clk_en != got + 2 * w + 4)) begin
                        errors = errors + 1;
                        if (errors < 10)
                            $display("%0s %0dx%0d gaps=%0d: output %0d = %0d at enabled clock %0d, want %0d at %0d",
                                     name, w, h, gaps, got, cd, clk_en, ref[got], got + 2 * w + 4);
                    end
                    got = got + 1;
                end
                if (en && in_valid) fed = fed + 1;
                if (en) clk_en = clk_en + 1;
                #1;
                tick;
                guard = guard + 1;
            end
            // Nothing after the last output, however long the stage is clocked.
            in_valid = 1'b0;
            repeat (3 * w + 8) begin
                en = 1'b1;
                #1;
                if (cv) begin
                    errors = errors + 1;
                    $display("%0s %0dx%0d gaps=%0d: extra output %0d", name, w, h, gaps, cd);
                end
                #1;
                tick;
            end
            if (got != w * h) begin
                errors = errors + 1;
                $display("%0s %0dx%0d gaps=%0d: %0d outputs of %0d", name, w, h, gaps, got, w * h);
            end
        end
    endtask

    task both;
        input integer w, h;
        input [8*24-1:0] name;
        begin
            run(w, h, 0, name);
            run(w, h, 1, name);
        end
    endtask

    integer i, n, sz;
    integer ws [0:4];
    integer hs [0:4];
    initial begin
        ws[0] = 3;  hs[0] = 3;
        ws[1] = 5;  hs[1] = 4;
        ws[2] = 8;  hs[2] = 6;
        ws[3] = 16; hs[3] = 7;
        ws[4] = 13; hs[4] = 16;
        for (sz = 0; sz < 5; sz = sz + 1) begin
            n = ws[sz] * hs[sz];
            for (i = 0; i < n; i = i + 1) img[i] = 16'hABCD;
            both(ws[sz], hs[sz], "flat");
            for (i = 0; i < n; i = i + 1) img[i] = 16'd0;
            img[(hs[sz] / 2) * ws[sz] + ws[sz] / 2] = 16'd1024;
            both(ws[sz], hs[sz], "impulse");
            for (i = 0; i < n; i = i + 1) img[i] = 16'd0;
            img[0] = 16'd1024;
            img[n - 1] = 16'd1024;
            img[ws[sz] - 1] = 16'hFFFF;
            both(ws[sz], hs[sz], "corners");
            for (i = 0; i < n; i = i + 1) begin
                step_lfsr;
                img[i] = lfsr[15:0];
            end
            both(ws[sz], hs[sz], "random");
        end
        if (errors == 0) $display("PASS tb_conv");
        else $display("FAIL tb_conv: %0d errors", errors);
        $finish;
    end
endmodule

`default_nettype wire
