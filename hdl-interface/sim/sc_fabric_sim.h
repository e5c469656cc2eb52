/* C interface of the Verilated sc_fabric (the contract co-simulation's shim, see README.md).
 * The layout of every struct is mirrored by #[repr(C)] structs in tests/src/rtl_fabric.rs. */
#ifndef SC_FABRIC_SIM_H
#define SC_FABRIC_SIM_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* sc_fabric's parameters the model was built with (tests/build.rs passes them to Verilator
 * with -G and to this shim with -D). */
typedef struct {
    uint32_t w0, w1, w2, w3;
    uint32_t point_depth;
    uint32_t sobel_depth;
} sc_fabric_params;

/* The inputs of one clock (applied before its rising edge). */
typedef struct {
    uint32_t bus_wdata;
    uint8_t bus_addr;
    uint8_t bus_we;          /* one-clock write strobe */
    uint8_t bus_re;          /* one-clock read strobe */
    uint8_t pixel_valid;
    uint8_t pixel_data;
    uint8_t pixel_sof;
    uint8_t pixel_eol;
    uint8_t rst;             /* synchronous reset, active high */
    uint8_t pix_ce;          /* pixel-clock enable: the datapath advances on this clock */
    uint8_t link_ready;      /* LINK_OUT's TREADY */
} sc_fabric_in;

/* What one clock shows. */
typedef struct {
    uint32_t bus_rdata;      /* AFTER the rising edge: the word a read on this clock returns */
    uint8_t pixel_ready;     /* pixel_in_ready BEFORE the edge, with the inputs applied */
    uint8_t link_valid;      /* LINK_OUT's TVALID BEFORE the edge: with link_ready, */
    uint8_t link_data;       /* this byte left on the clock */
    uint8_t _pad;
} sc_fabric_out;

typedef struct sc_fabric_sim sc_fabric_sim;

/* A new model in its own VerilatedContext (inputs low, clk low), not yet reset; NULL on
 * failure. rand_seed = 0: every register and memory powers up 0; otherwise to random values
 * drawn from rand_seed (Verilator's randReset 2). */
sc_fabric_sim *sc_fabric_sim_new(uint32_t rand_seed);
/* Finalizes and frees the model. */
void sc_fabric_sim_free(sc_fabric_sim *sim);
/* One clock: the inputs applied with clk low, pixel_ready sampled, the rising edge, then
 * bus_rdata sampled. */
void sc_fabric_sim_clock(sc_fabric_sim *sim, const sc_fabric_in *in, sc_fabric_out *out);
/* The parameters, for the Rust side's check against its model's sizes. */
sc_fabric_params sc_fabric_sim_params(void);
/* Sizes of the structs, for the Rust side's layout check. */
uint32_t sc_fabric_sim_in_size(void);
uint32_t sc_fabric_sim_out_size(void);

#ifdef __cplusplus
}
#endif

#endif
