// Contract co-simulation shim: the Verilated sc_fabric behind the plain C interface of
// sc_fabric_sim.h. Built by tests/build.rs with the cc crate, beside sc_sim.cpp (the
// sc_frontend shim); the SC_FABRIC_* macros are the parameters Verilator was given.

#include "sc_fabric_sim.h"

#include <new>

#include "Vsc_fabric.h"
#include "verilated.h"

struct sc_fabric_sim {
    VerilatedContext *ctx;
    Vsc_fabric *top;
};

extern "C" {

sc_fabric_sim *sc_fabric_sim_new(uint32_t rand_seed) {
    sc_fabric_sim *s = new (std::nothrow) sc_fabric_sim;
    if (!s) return nullptr;
    s->ctx = new VerilatedContext;
    if (rand_seed != 0) {
        s->ctx->randReset(2);
        s->ctx->randSeed(static_cast<int>(rand_seed & 0x7fffffff));
    }
    s->top = new Vsc_fabric{s->ctx, "sc_fabric"};
    Vsc_fabric *t = s->top;
    t->clk = 0;
    t->rst = 0;
    t->bus_addr = 0;
    t->bus_wdata = 0;
    t->bus_we = 0;
    t->bus_re = 0;
    t->pixel_in_data = 0;
    t->pixel_in_valid = 0;
    t->pixel_in_sof = 0;
    t->pixel_in_eol = 0;
    t->pix_ce = 1;
    t->link_out_ready = 0;
    t->eval();
    return s;
}

void sc_fabric_sim_free(sc_fabric_sim *s) {
    if (!s) return;
    s->top->final();
    delete s->top;
    delete s->ctx;
    delete s;
}

void sc_fabric_sim_clock(sc_fabric_sim *s, const sc_fabric_in *in, sc_fabric_out *out) {
    Vsc_fabric *t = s->top;
    t->rst = in->rst ? 1 : 0;
    t->bus_addr = in->bus_addr;
    t->bus_wdata = in->bus_wdata;
    t->bus_we = in->bus_we ? 1 : 0;
    t->bus_re = in->bus_re ? 1 : 0;
    t->pixel_in_valid = in->pixel_valid ? 1 : 0;
    t->pixel_in_data = in->pixel_data;
    t->pixel_in_sof = in->pixel_sof ? 1 : 0;
    t->pixel_in_eol = in->pixel_eol ? 1 : 0;
    t->pix_ce = in->pix_ce ? 1 : 0;
    t->link_out_ready = in->link_ready ? 1 : 0;
    t->eval();
    out->pixel_ready = t->pixel_in_ready ? 1 : 0;
    out->link_valid = t->link_out_valid ? 1 : 0;
    out->link_data = t->link_out_data;

    t->clk = 1;
    t->eval();
    s->ctx->timeInc(1);
    out->bus_rdata = t->bus_rdata;
    t->clk = 0;
    t->eval();
    s->ctx->timeInc(1);
}

sc_fabric_params sc_fabric_sim_params(void) {
    return sc_fabric_params{SC_FABRIC_W0, SC_FABRIC_W1, SC_FABRIC_W2, SC_FABRIC_W3,
                            SC_FABRIC_POINT_DEPTH, SC_FABRIC_SOBEL_DEPTH};
}

uint32_t sc_fabric_sim_in_size(void) { return sizeof(sc_fabric_in); }

uint32_t sc_fabric_sim_out_size(void) { return sizeof(sc_fabric_out); }

}  // extern "C"
