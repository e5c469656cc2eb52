// Co-simulation shim: the Verilated sc_frontend behind the plain C interface of sc_sim.h.
// Built by tests/build.rs with the cc crate (next to the Verilator runtime and the C++ that
// `verilator --cc` generates into OUT_DIR).

#include "sc_sim.h"

#include <cstring>
#include <new>

#include "Vsc_frontend.h"
#include "verilated.h"

struct sc_sim {
    VerilatedContext *ctx;
    Vsc_frontend *top;
};

namespace {

// A port of up to 384 bits as little-endian 32-bit words.
struct Bits {
    uint32_t w[12];
    uint32_t get(int lsb, int width) const {
        uint64_t v = w[lsb / 32];
        if (lsb / 32 + 1 < 12) v |= static_cast<uint64_t>(w[lsb / 32 + 1]) << 32;
        v >>= lsb % 32;
        return static_cast<uint32_t>(v & ((uint64_t{1} << width) - 1));
    }
};

template <std::size_t N>
Bits wide(const VlWide<N> &v) {
    static_assert(N <= 12, "port wider than 384 bits");
    Bits b{};
    for (std::size_t i = 0; i < N; ++i) b.w[i] = v[i];
    return b;
}

Bits narrow(uint64_t v) {
    Bits b{};
    b.w[0] = static_cast<uint32_t>(v);
    b.w[1] = static_cast<uint32_t>(v >> 32);
    return b;
}

void edge(sc_sim *s) {
    s->top->clk = 1;
    s->top->eval();
    s->ctx->timeInc(1);
    s->top->clk = 0;
    s->top->eval();
    s->ctx->timeInc(1);
}

}  // namespace

extern "C" {

sc_sim *sc_sim_new(uint32_t rand_seed) {
    sc_sim *s = new (std::nothrow) sc_sim;
    if (!s) return nullptr;
    s->ctx = new VerilatedContext;
    if (rand_seed != 0) {
        s->ctx->randReset(2);
        s->ctx->randSeed(static_cast<int>(rand_seed & 0x7fffffff));
    }
    s->top = new Vsc_frontend{s->ctx, "sc_frontend"};
    s->top->clk = 0;
    s->top->start = 0;
    s->top->pix_valid = 0;
    s->top->ce = 1;
    s->top->pix_data = 0;
    s->top->eval();
    return s;
}

void sc_sim_free(sc_sim *s) {
    if (!s) return;
    s->top->final();
    delete s->top;
    delete s->ctx;
    delete s;
}

void sc_sim_start(sc_sim *s, const sc_sim_config *c) {
    Vsc_frontend *t = s->top;
    t->start = 1;
    t->cfg_width = c->width;
    t->cfg_height = c->height;
    t->cfg_octaves = c->octaves;
    t->cfg_contrast = c->contrast;
    t->cfg_edge_ratio = c->edge_ratio;
    t->cfg_sobel_scale = c->sobel_scale;
    t->cfg_max_offset = c->max_offset;
    t->pix_valid = 0;
    t->pix_data = 0;
    t->eval();
    edge(s);
    t->start = 0;
    t->eval();
}

void sc_sim_clock(sc_sim *s, int pix_valid, uint8_t pix_data, sc_sim_obs *o) {
    Vsc_frontend *t = s->top;
    t->pix_valid = pix_valid ? 1 : 0;
    t->pix_data = pix_data;
    t->eval();

    const Bits g = wide(t->g_data);
    const Bits d = wide(t->dog_data);
    const Bits sub = narrow(t->sub_data);
    const Bits pt = wide(t->pt_data);
    const Bits sb = wide(t->sb_data);
    for (int k = 0; k < 4; ++k) {
        o->en[k] = (t->oct_en >> k) & 1;
        for (int i = 0; i < 4; ++i) {
            o->g_valid[k][i] = (t->g_valid >> (k * 4 + i)) & 1;
            o->g[k][i] = static_cast<uint16_t>(g.get((k * 4 + i) * 16, 16));
        }
        o->dog_valid[k] = (t->dog_valid >> k) & 1;
        for (int j = 0; j < 3; ++j)
            o->dog[k][j] = static_cast<int16_t>(d.get((k * 3 + j) * 16, 16));
        o->sub_valid[k] = (t->sub_valid >> k) & 1;
        o->sub[k] = static_cast<uint16_t>(sub.get(k * 16, 16));
        o->pt_valid[k] = (t->pt_valid >> k) & 1;
        for (int f = 0; f < 6; ++f)
            o->pt[k][f] = static_cast<uint16_t>(pt.get(k * 96 + f * 16, 16));
        o->sb_valid[k] = (t->sb_valid >> k) & 1;
        o->sb_x[k] = static_cast<uint16_t>(sb.get(k * 46, 16));
        o->sb_y[k] = static_cast<uint16_t>(sb.get(k * 46 + 16, 16));
        o->sb_mag[k] = static_cast<uint8_t>(sb.get(k * 46 + 32, 8));
        o->sb_ori[k] = static_cast<uint8_t>(sb.get(k * 46 + 40, 6));
    }

    edge(s);
    o->done = t->done ? 1 : 0;
}

uint32_t sc_sim_obs_size(void) { return sizeof(sc_sim_obs); }

}  // extern "C"
