// Self-checking testbench of sc_row_conv -> sc_col_conv, for each of the four kernels
// (taps.rs GAUSS_TAPS) at once, against a direct reference: the 2-D convolution with the outer
// product of the quantized taps, sum_i sum_j t_i t_j p(clamp(y+i-2), clamp(x+j-2)), replicated
// borders, rounded ONCE, (acc + 2^19) >> 20 (convolver.rs: the row stage keeps the exact 26-bit
// sum, the column stage rounds after both passes, so the separable pair equals this exactly).
// Frames: flat (unity DC gain: output = input), all 0xFFFF (the largest sums: row 1024 * 65535,
// column accumulator < 2^36, output 0xFFFF), a 0xFFFF/0 checkerboard, single impulses of 1024,
// 0x8000 and 0x200 (exact ties k * 2^20 + 2^19, where round half up matters), impulses at the
// corners (border replication) and pseudo-random images, some with 0xFFFF samples mixed in;
// sizes from 3x3 up to the line length, including 3-wide and 3-high frames (the fabric's
// minimum, config.rs). Each frame runs twice: with the enable high on every clock and an input
// on every enabled clock, where output n must leave exactly at enabled clock
// n + gaussian_latency(w) = n + 2w + 4; and with random enable and input gaps, where the outputs
// must come in raster order, all w*h of them, none more.
// Prints PASS tb_conv or the first mismatches and FAIL tb_conv.
`default_nettype none

module tb_conv;
    localparam W = 16;
    localparam K = 4;  // kernels
    // Kernel k at [k*50 +: 50], tap j of it at [j*10 +: 10] (taps.rs GAUSS_TAPS).
    localparam [4*50-1:0] TAPS = {
        {10'd130, 10'd238, 10'd288, 10'd238, 10'd130},
        {10'd57,  10'd249, 10'd412, 10'd249, 10'd57},
        {10'd18,  10'd229, 10'd530, 10'd229, 10'd18},
        {10'd35,  10'd244, 10'd466, 10'd244, 10'd35}};

    reg         clk = 1'b0, start = 1'b0, en = 1'b0, in_valid = 1'b0;
    reg  [15:0] in_data = 16'd0, width = 16'd0, height = 16'd0;
    reg  [31:0] total = 32'd0;
    wire [K-1:0]    cv;  // column-stage output valid of kernel k
    wire [K*16-1:0] cd;  // its data at [k*16 +: 16]

    genvar g;
    generate
        for (g = 0; g < K; g = g + 1) begin : g_kernel
            wire        rv;
            wire [25:0] rd;  // exact row sums
            sc_row_conv #(.TAPS(TAPS[g*50 +: 50])) u_row (
                .clk(clk), .start(start), .en(en), .width(width), .total(total),
                .in_valid(in_valid), .in_data(in_data), .out_valid(rv), .out_data(rd));
            sc_col_conv #(.W(W), .TAPS(TAPS[g*50 +: 50])) u_col (
                .clk(clk), .start(start), .en(en), .width(width), .height(height), .total(total),
                .in_valid(rv), .in_data(rd), .out_valid(cv[g]), .out_data(cd[g*16 +: 16]));

            // White-box: every row sum is exact and reaches the column stage's dot product
            // with all 26 bits (a lost low bit would change the rounded output only near a
            // tie, which the frames rarely hit).
            integer n, xc, yc, i;
            reg [5*26-1:0] want;
            always @(posedge clk) begin
                if (!start && en && u_row.emit && u_row.dot !== rowref[g*W*W + u_row.emitted]) begin
                    errors = errors + 1;
                    if (errors < 10)
                        $display("kernel %0d: row sum %0d = %0d, want %0d", g, u_row.emitted,
                                 u_row.dot, rowref[g*W*W + u_row.emitted]);
                end
                if (!start && en && u_col.emit) begin
                    n  = u_col.emitted;
                    xc = n % width;
                    yc = n / width;
                    for (i = 0; i < 5; i = i + 1)
                        want[i*26 +: 26] = rowref[g*W*W + clampi(yc+i-2, height-1)*width + xc];
                    if (u_col.u_dot.s !== want) begin
                        errors = errors + 1;
                        if (errors < 10)
                            $display("kernel %0d: column taps of output %0d = %h, want %h", g, n,
                                     u_col.u_dot.s, want);
                    end
                end
            end
        end
    endgenerate

    // The column stage's dot product alone, at exact ties: four random row sums, the fifth
    // (G0's tap 0, 35, odd) solved so that the sum is k * 2^20 + 2^19 + d, d = -1, 0, 1
    // (rounds to k, k + 1, k + 1). The rounded unit against the exact one (SH = 0).
    reg  [5*26-1:0] ds;
    wire [15:0]     dy;
    wire [35:0]     dexact;
    sc_da_dot #(.TAPS(TAPS[0 +: 50]), .IW(26), .SH(20)) u_dround (.s(ds), .y(dy));
    sc_da_dot #(.TAPS(TAPS[0 +: 50]), .IW(26), .SH(0))  u_dexact (.s(ds), .y(dexact));

    task ties;
        integer t, j, d;
        reg [47:0] part, inv, r0, sum;
        begin
            // inverse of tap 0 modulo 2^20 (Newton: each step doubles the correct low bits)
            inv = tap(0, 0);
            repeat (5) inv = (inv * (48'd2 - tap(0, 0) * inv)) & 48'hFFFFF;
            for (t = 0; t < 2000; t = t + 1) begin
                part = 48'd0;
                for (j = 1; j < 5; j = j + 1) begin
                    step_lfsr;
                    ds[j*26 +: 26] = lfsr[25:0] % 26'd67107841;  // <= 1024 * 65535
                    part = part + tap(0, j) * ds[j*26 +: 26];
                end
                step_lfsr;
                for (d = -1; d <= 1; d = d + 1) begin
                    // r0 = (2^19 + d - part) / tap0 mod 2^20, plus random multiples of 2^20
                    r0 = (((48'd1 << 19) + d - part) * inv) & 48'hFFFFF;
                    r0 = r0 + ({28'd0, lfsr[5:0]} << 20);
                    ds[0 +: 26] = r0[25:0];
                    sum = part + tap(0, 0) * r0;
                    #1;
                    if (sum[19:0] !== 20'h80000 + d || dexact !== sum[35:0]
                        || dy !== ((sum + (48'd1 << 19)) >> 20)) begin
                        errors = errors + 1;
                        if (errors < 10)
                            $display("da tie %0d d=%0d: sum %h, exact %h, rounded %h",
                                     t, d, sum, dexact, dy);
                    end
                    checked = checked + 1;
                end
            end
        end
    endtask

    reg [15:0] img [0:W*W-1];
    reg [15:0] ref [0:K*W*W-1];     // kernel k, pixel n at k*W*W + n
    reg [25:0] rowref [0:K*W*W-1];  // exact row sums, likewise
    integer errors = 0;
    integer checked = 0;
    reg [31:0] lfsr = 32'h1234_5678;

    function integer clampi;
        input integer v, mx;
        clampi = (v < 0) ? 0 : (v > mx) ? mx : v;
    endfunction

    function integer tap;
        input integer k, j;
        tap = TAPS[k*50 + j*10 +: 10];
    endfunction

    task step_lfsr;
        lfsr = {lfsr[30:0], lfsr[31] ^ lfsr[21] ^ lfsr[1] ^ lfsr[0]};
    endtask

    // Direct 2-D convolution, one rounding: sums up to 2^20 * 65535 + 2^19 < 2^36. Also the
    // exact row sums, for the white-box checks of the row->column path below.
    task reference;
        input integer w, h;
        integer k, x, y, i, j;
        reg [47:0] acc;
        begin
            for (k = 0; k < K; k = k + 1)
                for (y = 0; y < h; y = y + 1)
                    for (x = 0; x < w; x = x + 1) begin
                        acc = 48'd0;
                        for (j = 0; j < 5; j = j + 1)
                            acc = acc + tap(k, j) * img[y*w + clampi(x+j-2, w-1)];
                        rowref[k*W*W + y*w + x] = acc[25:0];
                    end
            for (k = 0; k < K; k = k + 1)
                for (y = 0; y < h; y = y + 1)
                    for (x = 0; x < w; x = x + 1) begin
                        acc = 48'd1 << 19;
                        for (i = 0; i < 5; i = i + 1)
                            for (j = 0; j < 5; j = j + 1)
                                acc = acc + tap(k, i) * tap(k, j)
                                          * img[clampi(y+i-2, h-1)*w + clampi(x+j-2, w-1)];
                        ref[k*W*W + y*w + x] = acc[35:20];
                    end
        end
    endtask

    task tick;
        begin
            #1 clk = 1'b1;
            #1 clk = 1'b0;
        end
    endtask

    // Runs one frame; gaps = 0: en always high and an input on every enabled clock. The four
    // kernels share the input and the latency, so their outputs leave on the same clocks.
    task run;
        input integer w, h, gaps;
        input [8*24-1:0] name;
        integer fed, got, clk_en, guard, k;
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
                if (en && cv !== {K{1'b0}}) begin
                    for (k = 0; k < K; k = k + 1) begin
                        if (cv[k] !== 1'b1 || cd[k*16 +: 16] !== ref[k*W*W + got]
                            || (!gaps && clk_en != got + 2 * w + 4)) begin
                            errors = errors + 1;
                            if (errors < 10)
                                $display("%0s %0dx%0d gaps=%0d kernel %0d: output %0d = %0d (valid %b) at enabled clock %0d, want %0d at %0d",
                                         name, w, h, gaps, k, got, cd[k*16 +: 16], cv[k], clk_en,
                                         ref[k*W*W + got], got + 2 * w + 4);
                        end
                        checked = checked + 1;
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
                if (cv !== {K{1'b0}}) begin
                    errors = errors + 1;
                    $display("%0s %0dx%0d gaps=%0d: extra output, valid %b", name, w, h, gaps, cv);
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

    task fill;
        input integer n;
        input [15:0] v;
        integer i;
        for (i = 0; i < n; i = i + 1) img[i] = v;
    endtask

    localparam NS = 9;
    integer i, n, sz, wd, ht;
    integer ws [0:NS-1];
    integer hs [0:NS-1];
    initial begin
        ws[0] = 3;  hs[0] = 3;
        ws[1] = 5;  hs[1] = 4;
        ws[2] = 8;  hs[2] = 6;
        ws[3] = 16; hs[3] = 7;
        ws[4] = 13; hs[4] = 16;
        ws[5] = 3;  hs[5] = 16;
        ws[6] = 16; hs[6] = 3;
        ws[7] = 4;  hs[7] = 3;
        ws[8] = 16; hs[8] = 16;
        ties;
        for (sz = 0; sz < NS; sz = sz + 1) begin
            wd = ws[sz]; ht = hs[sz]; n = wd * ht;
            fill(n, 16'hABCD);
            both(wd, ht, "flat");
            fill(n, 16'hFFFF);
            both(wd, ht, "max");
            for (i = 0; i < n; i = i + 1) img[i] = ((i % wd + i / wd) % 2) ? 16'hFFFF : 16'h0000;
            both(wd, ht, "checkerboard");
            fill(n, 16'd0);
            img[(ht / 2) * wd + wd / 2] = 16'd1024;
            both(wd, ht, "impulse 1024");
            img[(ht / 2) * wd + wd / 2] = 16'h8000;
            both(wd, ht, "impulse 0x8000");
            img[(ht / 2) * wd + wd / 2] = 16'h0200;
            both(wd, ht, "impulse 0x200");
            fill(n, 16'd0);
            img[0] = 16'd1024;
            img[n - 1] = 16'd1024;
            img[wd - 1] = 16'hFFFF;
            img[n - wd] = 16'h8000;
            both(wd, ht, "corners");
            for (i = 0; i < n; i = i + 1) begin
                step_lfsr;
                img[i] = lfsr[15:0];
            end
            both(wd, ht, "random");
            for (i = 0; i < n; i = i + 1) begin
                step_lfsr;
                img[i] = lfsr[4] ? 16'hFFFF : lfsr[5] ? lfsr[15:0] : {lfsr[7:0], 8'h00};
            end
            both(wd, ht, "random with 0xFFFF");
        end
        if (errors == 0) $display("PASS tb_conv (%0d outputs checked)", checked);
        else $display("FAIL tb_conv: %0d errors", errors);
        $finish;
    end
endmodule

`default_nettype wire
