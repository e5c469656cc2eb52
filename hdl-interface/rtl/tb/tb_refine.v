// Vector testbench of the pipelined sc_refine against records generated from the Rust model
// (run.sh, tb/vecgen.rs), record layout as tb_comb.v had it:
//   refine: {ds(16), dy(16), dx(16), ok(4), max_offset(16), cube(432)}  (offsets checked if ok)
// The candidates enter one per enabled clock, with idle clocks (in_valid low) and disabled
// clocks (en low) mixed in; before every enabled edge the output register must hold the
// result of the candidate that entered REFINE_LATENCY = L enabled clocks earlier (valid only
// if ok, payload x, y, dog = c(1,1,1) and dx, dy, ds), and `busy` must be set exactly while a
// candidate is in stages 1..L-1 or an accepted one in the output register. A `start` pulse in
// the middle clears the pipeline. max_offset is held per candidate (the octave's is constant
// within a frame): each record enters on its own, preceded by L idle enabled clocks, when its
// max_offset differs from the previous record's.
// Parameters: N (records), L (latency); file from +refine=.
`default_nettype none

module tb_refine;
    parameter N = 1, L = 18;

    reg [499:0] vr [0:N-1];

    reg          clk = 1'b0, en = 1'b0, start = 1'b0, in_valid = 1'b0;
    reg  [15:0]  in_x = 16'd0, in_y = 16'd0, maxo = 16'd0;
    reg  [431:0] cube = 432'd0;
    wire         out_valid, busy;
    wire [15:0]  out_x, out_y, out_dog, dx, dy, ds;

    sc_refine u_r (.clk(clk), .en(en), .start(start), .in_valid(in_valid), .in_x(in_x),
                   .in_y(in_y), .cube(cube), .max_offset(maxo), .out_valid(out_valid),
                   .out_x(out_x), .out_y(out_y), .out_dog(out_dog), .dx(dx), .dy(dy), .ds(ds),
                   .busy(busy));

    // Per enabled edge e: the record that entered (-1: none).
    integer hist [0:N*(2*L+8)+4*L+64];
    reg [1023:0] fname;
    integer i, e, j, m, r, bad, seed, want_busy;
    reg want_v, did_start;

    task edge_check;  // before enabled edge e
        begin
            want_v = 1'b0;
            if (e >= L && hist[e-L] >= 0) want_v = vr[hist[e-L]][448];
            want_busy = want_v;
            for (j = 1; j < L; j = j + 1)
                if (e >= j && hist[e-j] >= 0) want_busy = 1;
            if (out_valid !== want_v || busy !== (want_busy != 0)
                || (want_v && ({ds, dy, dx} !== vr[hist[e-L]][499:452]
                               || out_x !== hist[e-L][15:0] || out_y !== ~hist[e-L][15:0]
                               || out_dog !== vr[hist[e-L]][13*16 +: 16]))) begin
                bad = bad + 1;
                if (bad <= 5)
                    $display("refine edge %0d: got v=%b busy=%b %h %h %h x=%h y=%h dog=%h",
                             e, out_valid, busy, dx, dy, ds, out_x, out_y, out_dog);
            end
        end
    endtask

    task tick;  // one clock; e counts enabled edges
        begin
            if (en && !start) edge_check;
            #1 clk = 1'b1;
            #1 clk = 1'b0;
            if (en && !start) e = e + 1;
        end
    endtask

    task idle_en;  // one enabled clock without a candidate
        begin
            en = 1'b1; in_valid = 1'b0; hist[e] = -1; tick;
        end
    endtask

    task do_start;
        begin
            en = 1'b0; start = 1'b1; in_valid = 1'b0; tick;
            start = 1'b0;
            for (j = 0; j < e; j = j + 1) hist[j] = -1;
        end
    endtask

    initial begin
        bad = 0;
        did_start = 1'b0;
        seed = 1;
        e = 0;
        if (!$value$plusargs("refine=%s", fname)) begin
            $display("FAIL: no +refine=");
            $finish;
        end
        $readmemh(fname, vr);
        do_start;
        i = 0;
        while (i < N) begin
            r = $random(seed) & 15;
            if (i == N / 2 && !did_start) begin
                // Mid-stream start: drop what is in flight (the next checks expect nothing).
                do_start;
                did_start = 1'b1;
            end else if (r < 2) begin
                en = 1'b0; in_valid = 1'b1; tick;    // disabled clock: nothing moves
            end else if (r < 4) begin
                idle_en;
            end else begin
                if (i > 0 && vr[i][447:432] !== vr[i-1][447:432])
                    for (m = 0; m < L; m = m + 1) idle_en;
                en = 1'b1; in_valid = 1'b1;
                {maxo, cube} = vr[i][447:0];
                in_x = i[15:0]; in_y = ~i[15:0];
                hist[e] = i;
                tick;
                i = i + 1;
            end
        end
        for (m = 0; m < L + 2; m = m + 1) idle_en;
        if (busy !== 1'b0) begin
            bad = bad + 1;
            $display("refine: busy after the flush");
        end
        $display("sc_refine: %0d vectors, %0d mismatches", N, bad);
        if (bad == 0) $display("PASS");
        else $display("FAIL: %0d mismatches", bad);
        $finish;
    end
endmodule

`default_nettype wire
