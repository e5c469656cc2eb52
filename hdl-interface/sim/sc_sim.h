/* C interface of the Verilated sc_frontend (co-simulation shim, see README.md).
 * The layout of every struct is mirrored by #[repr(C)] structs in tests/src/rtl.rs. */
#ifndef SC_SIM_H
#define SC_SIM_H

#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* The cfg_* inputs of sc_frontend, latched by the start pulse. */
typedef struct {
    uint16_t width;
    uint16_t height;
    uint8_t octaves;       /* 1..4 */
    uint8_t edge_ratio;
    uint8_t sobel_scale;   /* 0..3 */
    uint8_t _pad;
    uint16_t contrast;     /* Q8.8 */
    uint16_t max_offset;   /* Q2.13 raw */
} sc_sim_config;

/* The observation ports of sc_frontend during one clock (before its rising edge), unpacked
 * per octave k = 0..3. Data fields are meaningful only where the matching valid is 1. */
typedef struct {
    uint8_t en[4];          /* oct_en[k] */
    uint8_t g_valid[4][4];  /* g_valid[k*4+i] */
    uint16_t g[4][4];       /* g_data[(k*4+i)*16 +: 16] */
    uint8_t dog_valid[4];   /* dog_valid[k] */
    int16_t dog[4][3];      /* dog_data[(k*3+j)*16 +: 16] */
    uint8_t sub_valid[4];   /* sub_valid[k] */
    uint16_t sub[4];        /* sub_data[k*16 +: 16] */
    uint8_t pt_valid[4];    /* pt_valid[k] */
    uint16_t pt[4][6];      /* pt_data[k*96 +: 96]: x, y, dx, dy, ds, dog (lowest first) */
    uint8_t sb_valid[4];    /* sb_valid[k] */
    uint16_t sb_x[4];       /* sb_data[k*46 +: 16] */
    uint16_t sb_y[4];       /* sb_data[k*46+16 +: 16] */
    uint8_t sb_mag[4];      /* sb_data[k*46+32 +: 8] */
    uint8_t sb_ori[4];      /* sb_data[k*46+40 +: 6] */
    uint8_t done;           /* done, AFTER the rising edge */
} sc_sim_obs;

typedef struct sc_sim sc_sim;

/* A new model in its own VerilatedContext (inputs low, clk low); NULL on failure.
 * rand_seed = 0: every register and memory powers up 0; otherwise they power up to random
 * values drawn from rand_seed (Verilator's randReset 2). */
sc_sim *sc_sim_new(uint32_t rand_seed);
/* Finalizes and frees the model. */
void sc_sim_free(sc_sim *sim);
/* One clock with start = 1, cfg_* = *cfg and pix_valid = 0 (= start_frame). */
void sc_sim_start(sc_sim *sim, const sc_sim_config *cfg);
/* One clock with start = 0 and the pixel inputs: the observation ports are sampled with
 * clk low and the inputs applied, then the rising edge; obs->done is read after the edge. */
void sc_sim_clock(sc_sim *sim, int pix_valid, uint8_t pix_data, sc_sim_obs *obs);
/* Size of sc_sim_obs, for the Rust side's layout check. */
uint32_t sc_sim_obs_size(void);

#ifdef __cplusplus
}
#endif

#endif
