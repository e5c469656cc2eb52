// Vector testbench of the combinational RTL-B modules (sc_extrema, sc_edge, sc_sobel; the
// pipelined sc_refine has tb_refine.v) against records generated from the Rust model (run.sh).
// Each record is one $readmemh line, most significant field first:
//   extrema: {is_ext(4), threshold(16), cube(432)}
//   edge:    {pass(4), ratio(8), d(144)}
//   sobel:   {sy(20), sx(20), p(144)}
// Parameters: N (records per file); files from +extrema=, +edge=, +sobel=.
`default_nettype none

module tb_comb;
    parameter NX = 1, NE = 1, NS = 1;

    reg [451:0] vx [0:NX-1];
    reg [155:0] ve [0:NE-1];
    reg [183:0] vs [0:NS-1];

    reg  [431:0] cube;
    reg  [15:0]  thr;
    reg  [143:0] d, p;
    reg  [7:0]   ratio;
    wire         is_ext, pass;
    wire signed [18:0] sx, sy;

    sc_extrema u_x (.cube(cube), .threshold(thr), .is_ext(is_ext));
    sc_edge    u_e (.d(d), .ratio(ratio), .pass(pass));
    sc_sobel   u_s (.p(p), .sx(sx), .sy(sy));

    reg [1023:0] fname;
    integer i, bad, total_bad;

    initial begin
        total_bad = 0;

        if ($value$plusargs("extrema=%s", fname)) begin
            $readmemh(fname, vx);
            bad = 0;
            for (i = 0; i < NX; i = i + 1) begin
                {thr, cube} = vx[i][447:0];
                #1;
                if (is_ext !== vx[i][448]) begin
                    bad = bad + 1;
                    if (bad <= 5) $display("extrema %0d: got %b want %b", i, is_ext, vx[i][448]);
                end
            end
            $display("sc_extrema: %0d vectors, %0d mismatches", NX, bad);
            total_bad = total_bad + bad;
        end

        if ($value$plusargs("edge=%s", fname)) begin
            $readmemh(fname, ve);
            bad = 0;
            for (i = 0; i < NE; i = i + 1) begin
                {ratio, d} = ve[i][151:0];
                #1;
                if (pass !== ve[i][152]) begin
                    bad = bad + 1;
                    if (bad <= 5) $display("edge %0d: got %b want %b", i, pass, ve[i][152]);
                end
            end
            $display("sc_edge: %0d vectors, %0d mismatches", NE, bad);
            total_bad = total_bad + bad;
        end

        if ($value$plusargs("sobel=%s", fname)) begin
            $readmemh(fname, vs);
            bad = 0;
            for (i = 0; i < NS; i = i + 1) begin
                p = vs[i][143:0];
                #1;
                // The model's Sx, Sy must also be 19-bit values (bits 19 = bits 18).
                if (sx !== vs[i][162:144] || sy !== vs[i][182:164]
                    || vs[i][163] !== vs[i][162] || vs[i][183] !== vs[i][182]) begin
                    bad = bad + 1;
                    if (bad <= 5) $display("sobel %0d: got %h %h want %h", i, sx, sy, vs[i][183:144]);
                end
            end
            $display("sc_sobel: %0d vectors, %0d mismatches", NS, bad);
            total_bad = total_bad + bad;
        end

        if (total_bad == 0) $display("PASS");
        else $display("FAIL: %0d mismatches", total_bad);
        $finish;
    end
endmodule

`default_nettype wire
