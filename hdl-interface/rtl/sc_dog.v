// sc_dog: one difference of Gaussians sample (mirrors dog.rs `dog`): d = b - a, saturated to
// i16. Combinational; the octave holds the three DoG samples of a pixel in its DoG register.
//
// Widths: a, b u16 Q8.8 scale samples; the difference needs 17 bits signed; the result is i16
// Q8.8 saturated at -32768 / 32767 (adjacent scales never come near +-128 grey levels).
`default_nettype none

module sc_dog (
    input  wire [15:0] a,  // G_i, u16 Q8.8
    input  wire [15:0] b,  // G_{i+1}, u16 Q8.8
    output wire [15:0] d   // i16 Q8.8, saturated
);

    wire signed [16:0] diff = $signed({1'b0, b}) - $signed({1'b0, a});  // -65535..65535

    assign d = (diff > 17'sd32767)  ? 16'h7fff :
               (diff < -17'sd32768) ? 16'h8000 : diff[15:0];

endmodule

`default_nettype wire
