// sc_framer: the stream engine's framer. It takes a packet's bytes (header and payload, as
// the wire format lays them out), appends their CRC-32C, COBS-encodes the packet, protects
// the COBS body by RS(255,239) parity packed seven bits per byte when `fec` was set at the
// packet's first byte, and ends the link frame with its 0x00 delimiter: the bytes
// `Framer::send` (firmware/src/framing/sink.rs) writes, byte for byte (shared/docs/
// wire-format.md, sections 2, 2.1 and 3; tests/tests/rtl_framer.rs compares them).
//
// Interfaces: IN (the packet former) and OUT (LINK_OUT) are byte streams with AXI4-stream
// rules (a byte moves on a clock where VALID and READY are both 1). IN_LAST marks a packet's
// last byte. A packet is at most MAXLEN - 4 bytes (the wire's MAX_PACKET_LEN minus its CRC);
// IN_READY stays 0 while a frame is being sent.
//
// How: the packet and its CRC go into a byte memory while they arrive (one byte per clock),
// and COBS's block codes into a code memory as the bytes that end the blocks arrive: a zero
// ends a block (code: its length plus one; the zero is not sent), a 254th non-zero byte ends
// a full one (code 0xFF), and the clock after the last byte ends the last block, except after
// a full one (a packet ending in a zero gets a last empty block, code 0x01). Then each block's
// code goes out and its bytes, one per clock. Every body byte that goes out also steps the
// RS shift register (generator (x - 2^0)..(x - 2^15) over GF(2^8) mod 0x11D); each 239
// bytes, and at the body's end, its 16 parity bytes go to a parity memory. After the body the
// parity bytes go out seven bits at a time, most significant first, each group with bit 7
// set, the last group's unused low bits 0; then the delimiter.
//
// The three memories have one write port and one read port whose data follows its address by
// a clock, the form block RAM takes (a 7 Series' RAMB18/36, an iCE40's SB_RAM40_4K): every
// state presents the addresses it reads on the next clock, so the memories cost one clock a
// packet (S_FIRST, which reads the first code after S_LAST wrote the last). The parity memory
// holds a block's 16 parity bytes as one 128-bit row, written whole when the block ends.
`default_nettype none

module sc_framer #(
    parameter MAXLEN = 2588              // packet and CRC: MAX_PACKET_LEN
) (
    input  wire       clk,
    input  wire       rst,               // synchronous, active high
    input  wire       fec,               // protect this packet (sampled at its first byte)
    input  wire [7:0] in_data,
    input  wire       in_valid,
    input  wire       in_last,
    output wire       in_ready,
    output reg  [7:0] out_data,
    output reg        out_valid,
    input  wire       out_ready
);

    localparam AW = $clog2(MAXLEN + 1);
    // Parity memory: 16 bytes per 239-byte block of the largest body (MAXLEN COBS-encoded).
    localparam BLOCKS = (MAXLEN + MAXLEN / 254 + 2 + 238) / 239;
    localparam PW = $clog2(16 * BLOCKS + 1);
    localparam [PW-1:0] ECC = 16;        // parity bytes per block

    localparam [3:0] S_IN = 4'd0,       // taking the packet's bytes
                     S_CRC = 4'd1,      // storing the 4 CRC bytes
                     S_LAST = 4'd2,     // the last block's code into the code memory
                     S_CODE = 4'd3,     // sending the block's code
                     S_DATA = 4'd4,     // sending the block's bytes
                     S_PARITY = 4'd5,   // the last block's parity into the memory
                     S_PACK = 4'd6,     // sending the packed parity
                     S_DELIM = 4'd7,    // sending the delimiter
                     S_FIRST = 4'd8;    // reading the first code

    reg  [3:0]    state;
    reg  [AW-1:0] n;                    // bytes stored (packet, then packet and CRC)
    reg  [AW-1:0] cn;                   // codes stored
    reg  [7:0]    run;                  // non-zero bytes of the block being stored, 0..253
    reg           full_end;             // the last byte stored ended a full block
    reg  [AW-1:0] ci;                   // the code being sent
    reg  [AW-1:0] p;                    // the block's first byte
    reg  [7:0]    k;                    // the block's length, 0..254
    reg           skip;                 // a zero ends the block (not sent)
    reg  [7:0]    j;                    // bytes of the block sent
    reg  [1:0]    crc_at;               // CRC byte being stored
    reg  [31:0]   crc;
    reg           protect;

    // RS shift register: rs[0] the highest degree; the block's bytes so far.
    reg  [7:0]    rs [0:15];
    reg  [7:0]    in_block;             // 0..239
    reg  [PW-1:0] par_n;                // parity bytes stored (16 per row)
    reg  [PW-1:0] par_at;               // parity bytes packed
    reg  [14:0]   bits;                 // packer: bits held, right-aligned
    reg  [3:0]    held;

    assign in_ready = state == S_IN;

    // ------------------------------------------------------------------------------------
    // Arithmetic.
    function [31:0] crc_byte(input [31:0] c, input [7:0] b);
        integer i;
        reg [31:0] x;
        begin
            x = c ^ {24'd0, b};
            for (i = 0; i < 8; i = i + 1)
                x = (x >> 1) ^ (32'h82F6_3B78 & {32{x[0]}});
            crc_byte = x;
        end
    endfunction

    function [7:0] gf_mul(input [7:0] a, input [7:0] b);   // GF(2^8) mod 0x11D
        integer i;
        reg [7:0] x, y;
        begin
            x = a;
            y = 8'd0;
            for (i = 0; i < 8; i = i + 1) begin
                if (b[i]) y = y ^ x;
                x = {x[6:0], 1'b0} ^ (x[7] ? 8'h1D : 8'h00);
            end
            gf_mul = y;
        end
    endfunction

    function [7:0] gen(input integer i);  // generator coefficient of degree 15 - i
        case (i)
            0: gen = 8'h3B;  1: gen = 8'h0D;  2: gen = 8'h68;  3: gen = 8'hBD;
            4: gen = 8'h44;  5: gen = 8'hD1;  6: gen = 8'h1E;  7: gen = 8'h08;
            8: gen = 8'hA3;  9: gen = 8'h41; 10: gen = 8'h29; 11: gen = 8'hE5;
           12: gen = 8'h62; 13: gen = 8'h32; 14: gen = 8'h24; default: gen = 8'h3B;
        endcase
    endfunction

    // ------------------------------------------------------------------------------------
    // The packet memory: written at `n` while the packet and its CRC arrive; `q` is the byte
    // at the address `ra` presented on the clock before.
    wire          we = !rst && (state == S_IN && in_valid || state == S_CRC);
    wire [7:0]    wd = state == S_IN ? in_data : ~crc[8*crc_at +: 8];
    reg  [AW-1:0] ra;
    wire [7:0]    q;
    sc_ram #(.DW(8), .DEPTH(MAXLEN), .AW(AW)) packet (
        .clk(clk), .we(we), .wa(n), .wd(wd), .re(1'b1), .ra(ra), .q(q)
    );

    // The code memory: a code is written at `cn` by the byte that ends its block, or on
    // S_LAST (at most one per byte, and the last); `cq` is the code at `cra` presented on the
    // clock before. S_FIRST reads the first code on the clock after S_LAST's write, which may
    // be that code.
    wire          ends_zero = we && wd == 8'd0;
    wire          ends_full = we && wd != 8'd0 && run == 8'd253;
    wire          cwe = ends_zero || ends_full || !rst && state == S_LAST && !full_end;
    wire [7:0]    cwd = ends_full ? 8'hFF : run + 8'd1;
    reg  [AW-1:0] cra;
    wire [7:0]    cq;
    sc_ram #(.DW(8), .DEPTH(MAXLEN + 1), .AW(AW)) codes (
        .clk(clk), .we(cwe), .wa(cn), .wd(cwd), .re(1'b1), .ra(cra), .q(cq)
    );

    // ------------------------------------------------------------------------------------
    // What goes out now.
    wire [AW-1:0] at = p + {{(AW-8){1'b0}}, k};          // the block's end
    wire [AW-1:0] data_at = p + {{(AW-8){1'b0}}, j};     // the byte going out (in q)
    wire [AW-1:0] next_p = at + {{(AW-1){1'b0}}, skip};  // the next block's first byte
    wire          body_byte = (state == S_CODE || state == S_DATA) && out_valid && out_ready;
    wire [7:0]    fb = out_data ^ rs[0];

    // The addresses for the next clock: the block's first byte and its code, the data byte
    // that goes out next (the next one once this one is taken), and at a block's end the next
    // block's first byte and code.
    always @(*) begin
        ra = {AW{1'b0}};
        cra = ci;
        case (state)
            S_CODE: ra = p;
            S_DATA: if (j != k) ra = data_at + {{(AW-1){1'b0}}, out_ready};
                    else begin
                        ra = next_p;
                        cra = ci + 1'b1;
                    end
            default: ;
        endcase
    end

    always @(*) begin
        out_valid = 1'b0;
        out_data = 8'd0;
        case (state)
            S_CODE: begin out_valid = 1'b1; out_data = cq; end
            S_DATA: begin out_valid = j != k; out_data = q; end
            S_PACK: begin
                out_valid = held >= 4'd7 || par_at == par_n && held != 4'd0;
                out_data = held >= 4'd7 ? {1'b1, bits[held - 4'd7 +: 7]}
                                        : {1'b1, bits[6:0] << (4'd7 - held)};
            end
            S_DELIM: out_valid = 1'b1;
            default: ;
        endcase
    end

    // ------------------------------------------------------------------------------------
    // The parity memory: a row is written when a block ends inside the body (its parity is
    // the shift register after the block's last byte) or at the body's end (the register as it
    // stands). The packer reads the row of the byte it packs next: a byte loaded gives it at
    // least seven bits to send, so a clock always lies between two loads, and the row read
    // there is the next byte's. A row read on the clock it is written (the body's only block,
    // at its end) is the written row (write-first). Byte r of a row is at bits 8r..8r+7.
    wire          block_end = body_byte && protect && in_block == 8'd238;
    wire          par_we = !rst && (block_end || state == S_PARITY && protect && in_block != 8'd0);
    wire [PW-5:0] par_wa = par_n[PW-1:4];
    wire [PW-5:0] par_ra = state == S_PACK ? par_at[PW-1:4] : {(PW-4){1'b0}};
    reg  [127:0]  rs_next;              // the shift register after the body byte going out
    reg  [127:0]  par_wd;
    wire [127:0]  par_row;
    integer       g;
    always @(*) begin
        for (g = 0; g < 15; g = g + 1) rs_next[8*g +: 8] = rs[g + 1] ^ gf_mul(fb, gen(g));
        rs_next[120 +: 8] = gf_mul(fb, gen(15));
        for (g = 0; g < 16; g = g + 1) par_wd[8*g +: 8] = block_end ? rs_next[8*g +: 8] : rs[g];
    end
    sc_ram #(.DW(128), .DEPTH(BLOCKS), .WRITE_FIRST(1), .AW(PW - 4)) parity (
        .clk(clk), .we(par_we), .wa(par_wa), .wd(par_wd), .re(1'b1), .ra(par_ra), .q(par_row)
    );

    integer r;
    always @(posedge clk) begin
        if (rst) begin
            state <= S_IN;
            n <= {AW{1'b0}};
            crc <= 32'hFFFF_FFFF;
            cn <= {AW{1'b0}};
            run <= 8'd0;
            full_end <= 1'b0;
        end else begin
            // Every byte stored: a zero or a full block's last byte ends the block.
            if (we) begin
                run <= ends_zero || ends_full ? 8'd0 : run + 8'd1;
                full_end <= ends_full;
            end
            if (cwe) cn <= cn + 1'b1;
            case (state)
                S_IN: if (in_valid) begin
                    if (n == {AW{1'b0}}) protect <= fec;
                    n <= n + 1'b1;
                    crc <= crc_byte(crc, in_data);
                    if (in_last) begin
                        state <= S_CRC;
                        crc_at <= 2'd0;
                    end
                end
                S_CRC: begin
                    n <= n + 1'b1;
                    crc_at <= crc_at + 2'd1;
                    if (crc_at == 2'd3) state <= S_LAST;
                end
                S_LAST: begin
                    state <= S_FIRST;
                    ci <= {AW{1'b0}};
                    p <= {AW{1'b0}};
                    in_block <= 8'd0;
                    par_n <= {PW{1'b0}};
                    for (r = 0; r < 16; r = r + 1) rs[r] <= 8'd0;
                end
                S_FIRST: state <= S_CODE;
                S_CODE: if (out_ready) begin
                    state <= S_DATA;
                    k <= cq - 8'd1;
                    skip <= cq != 8'hFF;
                    j <= 8'd0;
                end
                S_DATA: if (j != k) begin
                    if (out_ready) j <= j + 8'd1;
                end else begin
                    // The block's end; a zero that ended it is not sent.
                    p <= next_p;
                    ci <= ci + 1'b1;
                    state <= ci + 1'b1 == cn ? S_PARITY : S_CODE;
                end
                S_PARITY: begin
                    if (protect && in_block != 8'd0) par_n <= par_n + ECC;
                    par_at <= {PW{1'b0}};
                    bits <= 15'd0;
                    held <= 4'd0;
                    state <= protect ? S_PACK : S_DELIM;
                end
                S_PACK: begin
                    if (out_valid) begin
                        if (out_ready) begin
                            if (held >= 4'd7) held <= held - 4'd7;
                            else held <= 4'd0;
                        end
                    end else if (par_at != par_n) begin
                        bits <= {bits[6:0], par_row[8*par_at[3:0] +: 8]};
                        held <= held + 4'd8;
                        par_at <= par_at + 1'b1;
                    end else begin
                        state <= S_DELIM;
                    end
                end
                S_DELIM: if (out_ready) begin
                    state <= S_IN;
                    n <= {AW{1'b0}};
                    crc <= 32'hFFFF_FFFF;
                    cn <= {AW{1'b0}};
                    run <= 8'd0;
                    full_end <= 1'b0;
                end
                default: state <= S_IN;
            endcase

            // The RS shift register takes every body byte that goes out.
            if (body_byte && protect) begin
                if (in_block == 8'd238) begin
                    // The block's last byte: its parity goes to the memory, the register
                    // starts over.
                    par_n <= par_n + ECC;
                    in_block <= 8'd0;
                    for (r = 0; r < 16; r = r + 1) rs[r] <= 8'd0;
                end else begin
                    for (r = 0; r < 16; r = r + 1) rs[r] <= rs_next[8*r +: 8];
                    in_block <= in_block + 8'd1;
                end
            end
        end
    end

endmodule

`default_nettype wire
