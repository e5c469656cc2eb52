// sc_extrema: 3x3x3 extremum test of the DoG cube, = extrema::is_extremum (combinational;
// the octave holds the detector register, EXTREMA_LATENCY = 1).
//
// The centre c(1,1,1) is an extremum iff it is a strict maximum of the 27 samples above
// `threshold` or a strict minimum below -threshold (a plateau is no extremum).
//
// Widths: samples i16; threshold u16 (0..65535), so `v > t` and `v < -t` are compared in
// 17-bit signed (-t >= -65535 > -2^16). Neighbour comparisons are i16 against i16.
// Element (s,y,x) of `cube` is at bits [((s*3+y)*3+x)*16 +: 16]; the centre is element 13.
`default_nettype none

module sc_extrema (
    input  wire [27*16-1:0] cube,
    input  wire [15:0]      threshold,
    output wire             is_ext
);
    wire signed [15:0] v   = cube[13*16 +: 16];
    wire signed [16:0] v17 = {v[15], v};
    wire signed [16:0] t17 = {1'b0, threshold};

    wire is_max = v17 > t17;
    wire is_min = v17 < -t17;

    // ge[i]: neighbour i >= centre (spoils a maximum); le[i]: neighbour i <= centre.
    wire [26:0] ge, le;
    genvar i;
    generate
        for (i = 0; i < 27; i = i + 1) begin : g_cmp
            if (i == 13) begin : g_centre
                assign ge[i] = 1'b0;
                assign le[i] = 1'b0;
            end else begin : g_neighbour
                assign ge[i] = $signed(cube[i*16 +: 16]) >= v;
                assign le[i] = $signed(cube[i*16 +: 16]) <= v;
            end
        end
    endgenerate

    assign is_ext = (is_max && ge == 27'd0) || (is_min && le == 27'd0);
endmodule

`default_nettype wire
