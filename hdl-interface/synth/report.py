#!/usr/bin/env python3
"""Write docs/HARDWARE.md from one run of hdl-interface/synth/run.sh.

usage: report.py OUT_DIR HARDWARE_MD

Every number in the generated file comes from the run's yosys `stat -json` files, nextpnr's
`--report` JSON and logs, or from the Rust model's latency constants, except the published
reference figures (thesis, Vitis Vision, device capacities), which are quoted below with their
sources.
"""
import datetime
import glob
import json
import os
import re
import subprocess
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))

# ---- published reference figures (typed here, with their sources) ----
VITIS_DOG = {  # AMD/Xilinx Vitis Vision Library documentation, design example
    "source": "AMD/Xilinx Vitis Vision Library documentation, design example "
              "\"Difference of Gaussian Filter\", resource utilization table "
              "(1920x1080, 1 pixel/clock)",
    "lut": 15146, "ff": 22032, "bram": 19, "dsp": 193,
}
# Device capacities (vendor data sheets).
DEVICES = {
    "up5k": ("Lattice iCE40UP5K", 5280, 5280, 30, 8,
             "Lattice iCE40 UltraPlus data sheet (FPGA-DS-02008): 5,280 LUT4+FF, 30 EBR of 4 kbit, 8 DSP"),
    "hx8k": ("Lattice iCE40HX8K", 7680, 7680, 32, 0,
             "Lattice iCE40 LP/HX data sheet (DS1040): 7,680 LUT4+FF, 32 EBR of 4 kbit, no DSP"),
    "xc2v2000": ("Xilinx XC2V2000", 21504, 21504, 56, 56,
                 "Xilinx Virtex-II data sheet (DS031): 10,752 slices = 21,504 LUT4 and 21,504 FF, "
                 "56 SelectRAM blocks of 18 kbit, 56 MULT18X18"),
    "xc7a35t": ("Xilinx XC7A35T", 20800, 41600, 50, 90,
                "Xilinx 7 Series overview (DS180): 20,800 LUT6, 41,600 FF, 50 RAMB36, 90 DSP48E1"),
    "xc7a100t": ("Xilinx XC7A100T", 63400, 126800, 135, 240,
                 "Xilinx 7 Series overview (DS180): 63,400 LUT6, 126,800 FF, 135 RAMB36, 240 DSP48E1"),
    "xc7a200t": ("Xilinx XC7A200T", 134600, 269200, 365, 740,
                 "Xilinx 7 Series overview (DS180): 134,600 LUT6, 269,200 FF, 365 RAMB36, 740 DSP48E1"),
}

# ---- yosys stat parsing ----

def load_stat(path):
    """stat -json of yosys 0.23 (its hierarchy listing can leak into the JSON text)."""
    if not os.path.exists(path):
        return None
    txt = open(path).read()
    txt = "\n".join(l for l in txt.splitlines() if not re.match(r'^\s*[^\s"{}\[\]]', l))
    try:
        return json.loads(txt)["modules"]
    except (ValueError, KeyError):
        return None


def base_name(mod):
    """'$paramod$hash\\sc_linebuf' / '$paramod\\sc_col_conv\\W=..' / '\\sc_octave' -> 'sc_...'"""
    m = re.search(r"\\(sc_\w+)", mod)
    return m.group(1) if m else mod.lstrip("\\")


def params_of(mod):
    out = {}
    for k, bits in re.findall(r"\\(\w+)=s?\d*'([01]+)", mod):
        out[k] = int(bits, 2)
    return out


def param_map(log):
    """{module: {param: value}} from the derive messages of a yosys log (hashed $paramod names)."""
    out = {}
    if not os.path.exists(log):
        return out
    cur = {}
    for line in open(log, errors="replace"):
        if "Executing AST frontend in derive mode" in line:
            cur = {}
            continue
        m = re.match(r"Parameter \\(\w+) = (-?\d+)\s*$", line)
        if m:
            cur[m.group(1)] = int(m.group(2))
            continue
        m = re.match(r"Generating RTLIL representation for module `(.*)'\.", line)
        if m and cur:
            out[m.group(1)] = dict(cur)
            cur = {}
    return out


class Hier:
    def __init__(self, mods):
        self.mods = mods
        self.memo = {}

    def key(self, c):
        """Module key of a cell type (non-parametric modules appear without the backslash)."""
        if c in self.mods:
            return c
        if "\\" + c in self.mods:
            return "\\" + c
        return None

    def children(self, m):
        out = {}
        for c, n in self.mods[m]["num_cells_by_type"].items():
            k = self.key(c)
            if k is not None:
                out[k] = out.get(k, 0) + n
        return out

    def own(self, m):
        return {c: n for c, n in self.mods[m]["num_cells_by_type"].items() if self.key(c) is None}

    def total(self, m):
        if m in self.memo:
            return self.memo[m]
        t = dict(self.own(m))
        for c, n in self.children(m).items():
            for k, v in self.total(c).items():
                t[k] = t.get(k, 0) + n * v
        self.memo[m] = t
        return t

    def roots(self):
        used = set()
        for m in self.mods:
            used.update(self.children(m))
        return [m for m in self.mods if m not in used]

    def find(self, top):
        for m in self.mods:
            if base_name(m) == top:
                return m
        return None


def count(cells, pred):
    return sum(n for c, n in cells.items() if pred(c))


def summarise(family, cells):
    """Resource figures of one netlist: dict with lut, ff, bram, dsp, extra (text)."""
    if family == "ice40":
        lut = count(cells, lambda c: c == "SB_LUT4")
        ff = count(cells, lambda c: c.startswith("SB_DFF"))
        bram = count(cells, lambda c: c.startswith("SB_RAM40_4K"))
        dsp = count(cells, lambda c: c == "SB_MAC16")
        carry = count(cells, lambda c: c == "SB_CARRY")
        return dict(lut=lut, ff=ff, bram=bram, bram_txt=f"{bram} SB_RAM40_4K", dsp=dsp,
                    dsp_txt=f"{dsp} SB_MAC16", lut_txt=f"{lut:,} LUT4",
                    extra=f"{carry:,} SB_CARRY")
    if family == "xc7":
        luts = {k: count(cells, lambda c, k=k: c == f"LUT{k}") for k in range(1, 7)}
        lut = sum(luts.values())
        lutram = count(cells, lambda c: re.match(r"RAM(32|64|128|256)", c) is not None)
        srl = count(cells, lambda c: c.startswith("SRL"))
        ff = count(cells, lambda c: re.match(r"FD[RSCP]E", c) is not None)
        b18 = count(cells, lambda c: c.startswith("RAMB18"))
        b36 = count(cells, lambda c: c.startswith("RAMB36"))
        dsp = count(cells, lambda c: c.startswith("DSP48"))
        carry = count(cells, lambda c: c == "CARRY4")
        muxf = count(cells, lambda c: c in ("MUXF7", "MUXF8"))
        eq = b36 + b18 / 2
        return dict(lut=lut, ff=ff, bram=eq, dsp=dsp,
                    lut_txt=f"{lut:,} LUT (LUT6 {luts[6]:,}, LUT5 {luts[5]:,}, LUT1-4 {lut - luts[6] - luts[5]:,})",
                    bram_txt=f"{b36} RAMB36E1 + {b18} RAMB18E1 = {eq:g} RAMB36",
                    dsp_txt=f"{dsp} DSP48E1",
                    extra=f"{carry:,} CARRY4, {muxf:,} MUXF7/8, {lutram:,} LUT-RAM, {srl:,} SRL")
    if family == "xc2v":
        lut = count(cells, lambda c: re.match(r"LUT[1-4]$", c) is not None)
        lutram = count(cells, lambda c: re.match(r"RAM(16|32|64|128)X", c) is not None)
        srl = count(cells, lambda c: c.startswith("SRL"))
        ff = count(cells, lambda c: re.match(r"FD", c) is not None)
        bram = count(cells, lambda c: c.startswith("RAMB16"))
        dsp = count(cells, lambda c: c.startswith("MULT18X18"))
        muxf = count(cells, lambda c: c.startswith("MUXF"))
        carry = count(cells, lambda c: c in ("MUXCY", "XORCY"))
        lut1 = count(cells, lambda c: c == "LUT1")
        return dict(lut=lut, ff=ff, bram=bram, dsp=dsp, lut_txt=f"{lut:,} LUT4 (of which LUT1 {lut1:,})",
                    bram_txt=f"{bram} RAMB16", dsp_txt=f"{dsp} MULT18X18",
                    extra=f"{muxf:,} MUXF5-8, {carry:,} MUXCY/XORCY, {lutram:,} LUT-RAM, {srl:,} SRL")
    raise ValueError(family)


# ---- run bookkeeping ----

def read_status(out):
    st = {}
    p = os.path.join(out, "status.tsv")
    if os.path.exists(p):
        for line in open(p).read().splitlines()[1:]:
            f = line.split("\t")
            if len(f) >= 5:
                st[(f[0], f[1])] = (f[2], int(f[3] or 0), f[4])
    return st


def read_job(out, name):
    p = os.path.join(out, name, "job.txt")
    if not os.path.exists(p):
        return None
    f = open(p).read().split("\n")
    return dict(name=f[0], top=f[1], params=f[2], devs=f[3].split() if f[3] != "-" else [],
                what=f[4])


def pnr_result(out, name, dev):
    """(fmax MHz or None, utilisation dict name -> (used, avail), error text or None)."""
    d = os.path.join(out, name)
    rep = os.path.join(d, f"pnr-{dev}.report.json")
    log = os.path.join(d, f"pnr-{dev}.log")
    util, fmax, err = {}, None, None
    if os.path.exists(rep):
        try:
            r = json.load(open(rep))
            for k, v in r.get("utilization", {}).items():
                util[k] = (v["used"], v["available"])
            ach = [v["achieved"] for k, v in r.get("fmax", {}).items() if "clk" in k]
            if ach:
                fmax = min(ach)
        except ValueError:
            pass
    if os.path.exists(log):
        txt = open(log, errors="replace").read()
        if not util:
            for m in re.finditer(r"^Info:\s+(ICESTORM_\w+|SB_\w+):\s+(\d+)/\s*(\d+)", txt, re.M):
                util[m.group(1)] = (int(m.group(2)), int(m.group(3)))
        if fmax is None:
            ms = re.findall(r"Max frequency for clock '[^']*clk[^']*': ([\d.]+) MHz", txt)
            if ms:
                fmax = float(ms[-1])
        e = re.findall(r"^ERROR: (.*)$", txt, re.M)
        if e:
            err = e[0].strip()
    return fmax, util, err


def critical_path(out, name, dev):
    """Source and sink cell names of the worst clk->clk path from nextpnr's report."""
    rep = os.path.join(out, name, f"pnr-{dev}.report.json")
    try:
        r = json.load(open(rep))
    except (OSError, ValueError):
        return None
    for cp in r.get("critical_paths", []):
        if "clk" in cp.get("from", "") and "clk" in cp.get("to", "") and cp.get("path"):
            p = cp["path"]
            return p[0]["from"]["cell"], p[-1]["to"]["cell"], len(p)
    return None


def sta_ns(out, name):
    """Latest arrival time (ns) from the job's `sta` log (HX cell delays, no routing)."""
    p = os.path.join(out, name, "sta-hx.log")
    if not os.path.exists(p):
        return None
    m = re.findall(r"Latest arrival time in '[^']*' is (\d+)", open(p, errors="replace").read())
    return int(m[-1]) / 1000.0 if m else None


def rust_const(name):
    for f in glob.glob(os.path.join(REPO, "firmware/src/fabric/*.rs")):
        m = re.search(r"pub const %s: u32 = (\d+);" % name, open(f).read())
        if m:
            return int(m.group(1))
    return None


def sh(cmd):
    try:
        return subprocess.run(cmd, shell=True, capture_output=True, text=True, cwd=REPO).stdout.strip()
    except OSError:
        return ""


def fmt(x):
    if x is None:
        return "-"
    if isinstance(x, float):
        return f"{x:,.1f}" if x != int(x) else f"{int(x):,}"
    return f"{x:,}"


def pct(a, b):
    return f"{100.0 * a / b:.0f} %" if b else "-"


# ---- the document ----

def main():
    out, md_path = sys.argv[1], sys.argv[2]
    st = read_status(out)
    jobs = {}
    for p in sorted(glob.glob(os.path.join(out, "*", "job.txt"))):
        j = read_job(out, os.path.basename(os.path.dirname(p)))
        jobs[j["name"]] = j
    seconds = open(os.path.join(out, "seconds")).read().strip() if os.path.exists(os.path.join(out, "seconds")) else "?"
    started = open(os.path.join(out, "started")).read().strip() if os.path.exists(os.path.join(out, "started")) else "?"

    def rd(f):
        p = os.path.join(out, f)
        return open(p).read().strip() if os.path.exists(p) else "?"
    load = f"load average {rd('load_start')} at the start, {rd('load_end')} at the end"
    cpu = 0.0
    for lg in glob.glob(os.path.join(out, "*", "*.log")):
        if os.path.basename(lg).startswith("pnr-"):
            continue
        for u, sy in re.findall(r"CPU: user ([\d.]+)s system ([\d.]+)s", open(lg, errors="replace").read()):
            cpu += float(u) + float(sy)
    load += f"; the yosys steps used {cpu:,.0f} s of CPU in all"
    if seconds.isdigit() and cpu < 0.5 * int(seconds):
        load += ", so most of the wall time went to waiting for a core"

    def stat_of(name, fam, shell_aware=True):
        """(summary dict of the job's module, Hier, module key) or (None, None, None)."""
        fname = {"ice40": "ice40.stat.json", "xc7": "xc7.stat.json", "xc2v": "xc2v.stat.json",
                 "ice40hx": "ice40hx.stat.json"}[fam]
        mods = load_stat(os.path.join(out, name, fname))
        if not mods:
            return None, None, None
        h = Hier(mods)
        key = h.find(jobs[name]["top"])
        if key is None:
            return None, None, None
        return summarise("ice40" if fam.startswith("ice40") else fam, h.total(key)), h, key

    reruns = [line.split() for line in rd("reruns").splitlines()
               if len(line.split()) >= 4] if os.path.exists(os.path.join(out, "reruns")) else []
    L = []
    A = L.append
    yv = sh("yosys -V")
    nv = sh("nextpnr-ice40 --version 2>&1 | head -1")
    head = rd("rtl_commit") if os.path.exists(os.path.join(out, "rtl_commit")) else sh("git rev-parse --short HEAD")
    dirty_lines = (open(os.path.join(out, "rtl_dirty")).read() if os.path.exists(os.path.join(out, "rtl_dirty"))
                   else sh("git status --porcelain -- hdl-interface/rtl")).split("\n")
    dirty = ", ".join(sorted(os.path.basename(l[3:].rstrip("/")) + ("/" if l.endswith("/") else "")
                             for l in dirty_lines if l.strip()))
    A("# Hardware: synthesis of the fabric RTL")
    A("")
    A("Generated by `bash hdl-interface/synth/run.sh` (do not edit by hand: every figure below "
      "except the quoted reference figures comes from that run). "
      f"Run started {started}, "
      + (f"took **{fmt(int(seconds))} s** ({int(seconds) / 60:.1f} min)" if seconds.isdigit()
         else "its total time not recorded (the run ended before its bookkeeping; each step's "
              "time is in the last table)")
      + f" on this 2-core machine shared with other jobs ({load}"
      "). "
      f"Tools: {yv}; {nv}. RTL: `hdl-interface/rtl/` at commit {head}"
      + (f"; not committed at run time: {dirty}" if dirty else "") + "."
      + "".join(f" Jobs `{' '.join(r[2:-1])}` re-run on their own (SYNTH_ONLY) at {r[0]}, "
                f"RTL at commit {r[1]}, in {r[-1]} s." for r in reruns))
    A("")
    summary_at = len(L)
    A("What was synthesised (issue #7), at 640 px line width:")
    A("")
    for n in ("octave0", "frontend"):
        if n in jobs:
            j = jobs[n]
            A(f"- **{j['top']}** `#({j['params'].replace(' ', ', ')})`: {j['what']}.")
    A("")
    A("Targets and why:")
    A("")
    A("- `synth_xilinx -family xc7` (7 Series: LUT6, RAMB18E1/RAMB36E1, DSP48E1): the default "
      "family of yosys 0.23's `synth_xilinx`, not marked experimental, with block RAM, DSP and "
      "carry mapping; LUT6, 36 kbit block RAM and DSP48 are the same kinds of resource the "
      "Vitis Vision figures count. Hierarchy kept "
      "(the default), so the totals below break down per block. yosys gives no timing for "
      "Xilinx parts (no place and route here), so there is **no Fmax for Xilinx**.")
    A("- `synth_xilinx -family xc2v` (Virtex-II: LUT4, RAMB16, MULT18X18), the thesis' family; "
      "yosys marks it experimental. Resource counts only, octave only (it alone already exceeds "
      "the thesis' device, and it is the slowest step).")
    A("- `synth_ice40 -dsp` (iCE40 UltraPlus primitives: LUT4, SB_RAM40_4K, SB_MAC16), "
      "`-noflatten` so the module is its own hierarchy level (logic that a flattened synthesis "
      "would share between instances is counted in each: the line memories of one "
      "`sc_linebuf` are one `sc_ram` each and read one address, and each keeps its own "
      "registers for its block-RAM cascade), then `nextpnr-ice40` on the "
      "**iCE40UP5K** (the iCE40 with DSPs, package sg48) and, for blocks without DSP use or "
      "resynthesised without `-dsp`, the **iCE40HX8K** (the largest iCE40 nextpnr supports: "
      "7,680 logic cells, 32 block RAMs; ct256). Fixed seed 1, target "
      f"{50} MHz, `--timing-allow-fail`: the reported Fmax is what the router achieved.")
    A("")
    A("For place and route the module sits in a three-pin shell (`hdl-interface/synth/shell.py`: "
      "inputs from a serial shift register, outputs folded by a pipelined XOR tree, outputs of "
      "combinational modules registered), so no logic is optimised away and a single clock "
      "domain is timed register to register. The shell's own cells are not in the module "
      "figures; they are listed under the place-and-route table.")
    A("")

    # ---- main resource table ----
    A("## Resources")
    A("")
    A("| design | target | LUTs | flip-flops | block RAM | DSP / multipliers | other |")
    A("|---|---|---|---|---|---|---|")
    mains = {}
    for n in ("octave0", "frontend"):
        if n not in jobs:
            continue
        for fam, label in (("xc7", "xc7 (yosys)"), ("xc2v", "xc2v (yosys)"), ("ice40", "iCE40 UP (yosys, `-dsp`)")):
            s, h, k = stat_of(n, fam)
            stt = st.get((n, fam))
            if s is None and stt is None and fam == "xc2v" and n == "frontend":
                continue  # run.sh synthesises Virtex-II for the octave only
            if s is None:
                why = "not run" if stt is None else f"{stt[0]}: {stt[2]}"
                A(f"| {jobs[n]['top']} | {label} | {why} | | | | |")
                continue
            mains[(n, fam)] = (s, h, k)
            A(f"| {jobs[n]['top']} | {label} | {s['lut_txt']} | {fmt(s['ff'])} | {s['bram_txt']} | "
              f"{s['dsp_txt']} | {s['extra']} |")
    A("")

    # ---- fit against devices ----
    A("### Against device capacities")
    A("")
    A("| design | device | LUTs | FFs | block RAM | DSP | fits |")
    A("|---|---|---|---|---|---|---|")
    fam_dev = [("ice40", "up5k"), ("ice40", "hx8k"), ("xc2v", "xc2v2000"), ("xc7", "xc7a35t"), ("xc7", "xc7a100t"), ("xc7", "xc7a200t")]
    for n in ("octave0", "frontend"):
        for fam, dev in fam_dev:
            if (n, fam) not in mains:
                continue
            s = mains[(n, fam)][0]
            name, cl, cf, cb, cd = DEVICES[dev][:5]
            ok = s["lut"] <= cl and s["ff"] <= cf and s["bram"] <= cb and s["dsp"] <= cd
            A(f"| {jobs[n]['top']} | {name} | {fmt(s['lut'])} / {fmt(cl)} ({pct(s['lut'], cl)}) | "
              f"{fmt(s['ff'])} / {fmt(cf)} ({pct(s['ff'], cf)}) | {fmt(s['bram'])} / {cb} ({pct(s['bram'], cb)}) | "
              f"{fmt(s['dsp'])} / {cd} | {'yes' if ok else '**no**'} |")
    A("")
    A("iCE40 LUT counts are LUT4 before packing (a logic cell holds one LUT4 and one FF); "
      "the HX8K row uses the `-dsp` netlist, so its multipliers would become LUTs there. "
      "Capacities: " + "; ".join(f"{v[0]}: {v[5]}" for v in DEVICES.values()) + ".")
    A("")

    # ---- per-block breakdown ----
    A("## What dominates")
    A("")
    for n, fam in (("octave0", "xc7"), ("octave0", "ice40"), ("frontend", "xc7")):
        if (n, fam) not in mains:
            continue
        s, h, k = mains[(n, fam)]
        fam_s = "ice40" if fam == "ice40" else fam
        groups = {}
        pm = param_map(os.path.join(out, n, f"{fam}.log"))
        for c, cnt in h.children(k).items():
            t = summarise(fam_s, h.total(c))
            p = params_of(c) or pm.get(c, {})
            label = base_name(c)
            if label == "sc_octave" and p:
                label += " (" + ", ".join(f"{a}={b}" for a, b in p.items()) + ")"
            g = groups.setdefault(label, dict(n=0, lut=0, ff=0, bram=0, dsp=0))
            g["n"] += cnt
            for q in ("lut", "ff", "bram", "dsp"):
                g[q] += cnt * t[q]
        own = summarise(fam_s, h.own(k))
        groups[f"{base_name(k)} own logic (control, pipeline registers, muxes)"] = dict(
            n=1, lut=own["lut"], ff=own["ff"], bram=own["bram"], dsp=own["dsp"])
        rows = sorted(groups.items(), key=lambda r: -r[1]["lut"])
        A(f"**{jobs[n]['top']}, {fam}** (instances of a block summed):")
        A("")
        A("| block | instances | LUTs | % of LUTs | FFs | block RAM | DSP |")
        A("|---|---|---|---|---|---|---|")
        for bn, g in rows:
            A(f"| {bn} | {g['n']} | {fmt(g['lut'])} | {pct(g['lut'], s['lut'])} | "
              f"{fmt(g['ff'])} | {fmt(g['bram'])} | {fmt(g['dsp'])} |")
        A("")
        top3 = [r for r in rows if r[1]["lut"] > 0][:3]
        if top3:
            A("Largest by LUTs: " + ", ".join(
                f"{r[0]} ({pct(r[1]['lut'], s['lut'])})" for r in top3) + ".")
            A("")

    # the front end by block type over all four octaves
    for fam in ("xc7", "ice40"):
        if ("frontend", fam) not in mains:
            continue
        s, h, k = mains[("frontend", fam)]
        fam_s = "ice40" if fam == "ice40" else fam
        groups = {}

        def add(label, n, t):
            g = groups.setdefault(label, dict(n=0, lut=0, ff=0, bram=0, dsp=0))
            g["n"] += n
            for q in ("lut", "ff", "bram", "dsp"):
                g[q] += n * t[q]
        for c, cnt in h.children(k).items():
            for gc, m in h.children(c).items():
                add(base_name(gc), cnt * m, summarise(fam_s, h.total(gc)))
            add(f"{base_name(c)} own logic", cnt, summarise(fam_s, h.own(c)))
        add(f"{base_name(k)} own logic", 1, summarise(fam_s, h.own(k)))
        rows = sorted(groups.items(), key=lambda r: -r[1]["lut"])
        A(f"**sc_frontend, {fam}, by block over the four octaves:** "
          + ", ".join(f"{bn} x{g['n']} {pct(g['lut'], s['lut'])} of LUTs"
                      + (f" ({fmt(g['dsp'])} DSP)" if g["dsp"] else "")
                      for bn, g in rows if g["lut"] * 100 >= s["lut"]) + ".")
        A("")

    # ---- place and route ----
    A("## Place and route (nextpnr-ice40): Fmax")
    A("")
    A("| design | device | result | Fmax | logic cells | block RAM | DSP | logic-only delay (HX, `sta`) | critical path (from -> to) |")
    A("|---|---|---|---|---|---|---|---|---|")
    fmax_of = {}
    order = [n for n in ("octave0", "frontend") if n in jobs] + sorted(
        j for j in jobs if j not in ("octave0", "frontend"))
    for n in order:
        j = jobs[n]
        if not j["devs"]:
            A(f"| {j['top']} | - | not attempted: larger than the single octave (above) | - | | | | | |")
            continue
        for dev in j["devs"]:
            stt = st.get((n, f"pnr-{dev}"))
            pre = st.get((n, "ice40" if dev == "up5k" else "ice40-hx"))
            if stt is None:
                why = "not run" if pre is None or pre[0] == "ok" else f"synthesis {pre[0]}: {pre[2]}"
                dep = st.get((n, "deps"))
                if dep:
                    why = f"{dep[0]}: {dep[2]}"
                A(f"| {j['top']} {j['params']} | {dev} | {why} | - | | | | | |")
                continue
            fmax, util, err = pnr_result(out, n, dev)
            lc = util.get("ICESTORM_LC", (None, None))
            ram = util.get("ICESTORM_RAM", (None, None))
            dsp = util.get("ICESTORM_DSP", (0, 0))
            if stt[0] == "ok":
                res = "routed"
                fmax_of[(n, dev)] = fmax
            elif stt[0] == "timeout":
                res = f"**timed out** after {stt[1]} s"
            else:
                over = [f"{k} {u:,}/{a:,}" for k, (u, a) in util.items() if a and u > a]
                if over:
                    res = "**does not fit**: " + ", ".join(over)
                else:
                    res = f"**failed**: {err or stt[2]}"
            cp = critical_path(out, n, dev) if stt[0] == "ok" else None
            cpt = f"`{cp[0]}` -> `{cp[1]}`" if cp else ""
            sn = sta_ns(out, n) if dev == "hx8k" else None
            stt_txt = f"{sn:.1f} ns (<= {1000.0 / sn:.1f} MHz)" if sn else ""
            A(f"| {j['top']} {j['params']} | {dev} | {res} | {fmt(fmax) + ' MHz' if fmax and stt[0] == 'ok' else '-'} | "
              f"{fmt(lc[0])} / {fmt(lc[1])} | {fmt(ram[0])} / {fmt(ram[1])} | {fmt(dsp[0])} / {fmt(dsp[1])} | {stt_txt} | {cpt} |")
    A("")
    # shell overhead
    sh_rows = []
    for n in order:
        mods = load_stat(os.path.join(out, n, "ice40.stat.json"))
        if not mods:
            continue
        h = Hier(mods)
        k = h.find("sc_synth_shell")
        if k:
            o = summarise("ice40", h.own(k))
            sh_rows.append(f"{jobs[n]['top']} {o['lut']} LUT4 + {o['ff']} FF")
    if sh_rows:
        A("Logic cells above include the shell (" + "; ".join(sh_rows) + ").")
        A("")

    # ---- blocks ----
    A("## Blocks of one octave (iCE40, yosys, in the shell)")
    A("")
    A("| block | what | LUT4 | FF | SB_RAM40_4K | SB_MAC16 | status |")
    A("|---|---|---|---|---|---|---|")
    for n in order:
        if n in ("octave0", "frontend"):
            continue
        j = jobs[n]
        s, h, k = stat_of(n, "ice40")
        stt = st.get((n, "ice40")) or st.get((n, "deps"))
        if s is None:
            A(f"| {j['top']} {j['params']} | {j['what']} | | | | | {stt[0] + ': ' + stt[2] if stt else 'not run'} |")
            continue
        A(f"| {j['top']} {j['params']} | {j['what']} | {fmt(s['lut'])} | {fmt(s['ff'])} | {fmt(s['bram'])} | {fmt(s['dsp'])} | ok |")
    A("")

    # ---- the stream engine ----
    if "stream" in jobs:
        j = jobs["stream"]
        A("## The stream engine (7 Series)")
        A("")
        A(f"{j['top']} `#({j['params'].replace(' ', ', ')})`: {j['what']} "
          "(`docs/STREAM_ENGINE.md`). Its memories fit no iCE40's block RAM, so it is "
          "synthesised for the 7 Series only (`synth_xilinx -family xc7`, hierarchy kept).")
        A("")
        s7, h7, k7 = stat_of("stream", "xc7")
        stt = st.get(("stream", "xc7"))
        if s7 is None:
            A(f"Not synthesised: {stt[0] + ': ' + stt[2] if stt else 'not run'}.")
        else:
            A("| module | LUT | FF | block RAM | DSP | other |")
            A("|---|---|---|---|---|---|")
            A(f"| {j['top']} (all) | {s7['lut_txt']} | {fmt(s7['ff'])} | {s7['bram_txt']} | "
              f"{s7['dsp_txt']} | {s7['extra']} |")
            for child in h7.children(k7):
                c = summarise("xc7", h7.total(child))
                A(f"| {base_name(child)} | {c['lut_txt']} | {fmt(c['ff'])} | {c['bram_txt']} | "
                  f"{c['dsp_txt']} | {c['extra']} |")
        A("")

    # ---- reference figures ----
    A("## Reference figures")
    A("")
    A("**The thesis** (N. Pettersson, *Online Stereo Calibration using FPGAs*, MSc thesis, "
      "Chalmers 2005; full text in `../shared/reference/`) publishes **no LUT, flip-flop or "
      "block-RAM table** for its front end. What it states about the hardware:")
    A("")
    A("- Device: \"a PicProdigy development board from Atlantek Microsystems equipped with a "
      "Xilinx Virtex II FPGA with 2M gates\" (section 4.1.3), i.e. the XC2V2000 class "
      "(capacity above); the Gaussian pyramid shares it with Atlantek's buffering and PCI logic.")
    A("- Line buffers \"implemented in hardware using Xilinx native SelectRAMs\" (section 4.2.2); "
      "de-interlacing halves the lines buffered for the column filter \"from four to two\" "
      "(section 4.2.1).")
    A("- Figure 4.8 (section 4.2.4) plots \"an estimate of the area used in the FPGA\" in percent "
      "against kernel size 3 to 9; the 5-tap kernel was chosen \"as a trade-off between area "
      "usage on the FPGA and accuracy\". No figure is given as a number in the text.")
    A("- Clock: \"a pipeline clock of 54 MHz\" (section 5.2); input 640 x 240 fields at 60 Hz "
      "(section 4.1.2); four octaves, the fourth \"can be removed to save area in the FPGA\" "
      "(section 5.3).")
    A("")
    A(f"**Vitis Vision** DoG ({VITIS_DOG['source']}): {VITIS_DOG['lut']:,} LUT, "
      f"{VITIS_DOG['ff']:,} FF, {VITIS_DOG['bram']} BRAM, {VITIS_DOG['dsp']} DSP. That design is "
      "one difference of Gaussians as its documentation describes it (a Gaussian blur, the "
      "result duplicated, a second blur on one copy, a subtraction) on 1080p lines, written in "
      "HLS C++; the octave here computes four cascaded Gaussians, three DoGs, the 3x3x3 "
      "extremum, edge test, sub-pixel refinement, Sobel and CORDIC on 640 px lines, with "
      "multiplier-free distributed-arithmetic convolvers, so the figures are of the same "
      "order but not like for like.")
    A("")
    if ("octave0", "xc7") in mains:
        s = mains[("octave0", "xc7")][0]
        A(f"Side by side (7 Series class): this octave {fmt(s['lut'])} LUT, {fmt(s['ff'])} FF, "
          f"{fmt(s['bram'])} RAMB36, {fmt(s['dsp'])} DSP48E1; Vitis Vision DoG {VITIS_DOG['lut']:,} LUT, "
          f"{VITIS_DOG['ff']:,} FF, {VITIS_DOG['bram']} BRAM, {VITIS_DOG['dsp']} DSP.")
        A("")

    # ---- 640x240 at 60 Hz ----
    A("## Does 640 x 240 at 60 Hz fit?")
    A("")
    w, hgt, hz = 640, 240, 60
    act = w * hgt
    c = {k: rust_const(k) for k in ("ROW_LATENCY", "SUBSAMPLE_LATENCY", "DOG_LATENCY", "EXTREMA_LATENCY",
                                    "EDGE_LATENCY", "REFINE_LATENCY", "SOBEL_LATENCY", "CORDIC_LATENCY")}
    drain = None
    if all(v is not None for v in c.values()):
        def gl(x):
            return c["ROW_LATENCY"] + 2 * x + 1  # convolver.rs gaussian_latency
        widths = [w, (w + 1) // 2, (w + 3) // 4, (w + 7) // 8]
        filt = [4, 3, 3, 3]
        drain = sum(filt[k] * gl(widths[k]) + c["SUBSAMPLE_LATENCY"] for k in range(3))
        last = widths[3]
        to_point = filt[3] * gl(last) + c["DOG_LATENCY"] + last + 2 + c["EXTREMA_LATENCY"] + c["EDGE_LATENCY"] + c["REFINE_LATENCY"]
        to_sobel = filt[3] * gl(last) + last + 2 + c["SOBEL_LATENCY"] + c["CORDIC_LATENCY"]
        drain += max(to_point, to_sobel)
    need_act = act * hz / 1e6
    A(f"The fabric takes one pixel per enabled clock. A 640 x 240 field at 60 Hz is "
      f"{act:,} pixels, **{need_act:.3f} Mpixel/s**, so at least {need_act:.3f} MHz on average.")
    if drain:
        need = (act + drain) * hz / 1e6
        A(f"After the last pixel the four octaves drain (every clock enabled) for about "
          f"{drain:,} clocks (the octave-to-next-octave latencies of octaves 0-2 plus octave 3's "
          f"latency to its last point or Sobel pixel, from the latency formulas of "
          f"`firmware/src/fabric/latency.rs`), which must fit in the blanking: "
          f"({act:,} + {drain:,}) x {hz} = **{need:.2f} MHz** minimum clock if the pixels are "
          "buffered and fed back to back.")
    A("Fed straight from the NTSC digitiser instead, the fabric must run at the sampling clock: "
      "12.27 MHz for 640 square pixels per line (780 samples per line total), 13.5 MHz for "
      "ITU-R BT.601; the thesis ran its pipeline at 54 MHz.")
    A("")
    need_buf = (act + (drain or 0)) * hz / 1e6
    oct_f = fmax_of.get(("octave0", "up5k"))
    oct_st = st.get(("octave0", "pnr-up5k"))
    blocks = [n for n in order if n not in ("octave0", "frontend")]

    def verdict(f):
        if f >= 13.5:
            return "meets both the buffered rate and a direct 13.5 MHz feed"
        if f >= 12.27:
            return "meets the buffered rate and a 12.27 MHz square-pixel feed, not 13.5 MHz"
        if f >= need_buf:
            return f"meets the buffered rate ({need_buf:.2f} MHz) only"
        return f"is **below** even the buffered rate ({need_buf:.2f} MHz)"

    if oct_f and oct_st and oct_st[0] == "ok":
        A(f"- **The octave routed on the iCE40UP5K at {oct_f:.1f} MHz**: it {verdict(oct_f)}.")
    else:
        ice = mains.get(("octave0", "ice40"))
        hx = ""
        if ice:
            hx = (f" nor the iCE40HX8K ({fmt(ice[0]['lut'])} LUT4 and {fmt(ice[0]['bram'])} block RAMs "
                  f"needed, {fmt(DEVICES['hx8k'][1])} and {DEVICES['hx8k'][3]} present)")
        A("- **The octave fits neither the iCE40UP5K** (place-and-route table above)" + hx + ", so "
          "there is no routed Fmax for it; what follows are its blocks, each placed and routed alone, which "
          "bound but do not measure an octave's Fmax (an octave contains these paths and more "
          "routing pressure, so it is not expected to be faster than its slowest block).")
    for dev in ("up5k", "hx8k"):
        fs = {n: fmax_of[(n, dev)] for n in blocks if fmax_of.get((n, dev))}
        nofit = [n for n in blocks if dev in jobs[n]["devs"] and not fmax_of.get((n, dev))
                 and st.get((n, f"pnr-{dev}")) and st[(n, f"pnr-{dev}")][0] != "ok"]
        if not fs:
            continue
        worst = min(fs, key=fs.get)
        A(f"- {DEVICES[dev][0]}: routed blocks, slowest first: "
          + ", ".join(f"{jobs[n]['top']} {fs[n]:.1f} MHz" for n in sorted(fs, key=fs.get))
          + f". The slowest, {jobs[worst]['top']} at {fs[worst]:.1f} MHz, {verdict(fs[worst])}."
          + (f" Not placed on this device: {', '.join(jobs[n]['top'] for n in nofit)} (table above); "
             "the octave's Fmax there is bounded by them too, and unknown." if nofit else ""))
    # logic-only bound for blocks that did not route anywhere
    ratios = []
    for n in blocks:
        sn = sta_ns(out, n)
        f = fmax_of.get((n, "hx8k"))
        if sn and f:
            ratios.append((1000.0 / f) / sn)
    for n in blocks:
        if any(fmax_of.get((n, d)) for d in jobs[n]["devs"]):
            continue
        sn = sta_ns(out, n)
        if not sn:
            continue
        txt = (f"- {jobs[n]['top']} routed on no iCE40. Its logic-only register-to-register delay "
               f"with yosys' iCE40 HX cell timings (`sta`, no routing) is **{sn:.1f} ns**, i.e. at "
               f"most {1000.0 / sn:.1f} MHz before any routing delay")
        if ratios:
            lo, hi = min(ratios), max(ratios)
            txt += (f"; the blocks that did route on the HX8K took {lo:.1f}x to {hi:.1f}x their "
                    f"logic-only delay, which would put it near {1000.0 / (sn * hi):.1f}-"
                    f"{1000.0 / (sn * lo):.1f} MHz (an extrapolation, not a measurement)")
        bound = 1000.0 / sn
        if bound < need_buf:
            txt += (f". Its slowest stage alone keeps the octave below the "
                    f"{need_buf:.2f} MHz buffered rate on iCE40 HX fabric, before any routing")
        else:
            worst_all = [fmax_of[(m, "hx8k")] for m in blocks if fmax_of.get((m, "hx8k"))]
            if worst_all and bound * (1 / max(ratios) if ratios else 1) < min(worst_all):
                txt += ". It is the octave's slowest stage"
        A(txt + ".")
    A("- Xilinx: no Fmax from this flow (yosys has no timing model for place and route of "
      "Xilinx parts).")
    A("")
    # verdict, from the figures above
    routed_min = {}
    for dev in ("up5k", "hx8k"):
        fs = [fmax_of[(n, dev)] for n in blocks if fmax_of.get((n, dev))]
        if fs:
            routed_min[dev] = min(fs)
    slow_sta = [(n, sta_ns(out, n)) for n in blocks if sta_ns(out, n)
                and not any(fmax_of.get((n, d)) for d in jobs[n]["devs"])]
    v = f"**Verdict.** 640 x 240 at 60 Hz needs at least {need_buf:.2f} MHz. "
    if oct_f and oct_st and oct_st[0] == "ok":
        v += f"The octave routed at {oct_f:.1f} MHz on the iCE40UP5K: it {verdict(oct_f)}. "
    else:
        v += "On an iCE40 the question is moot for the octave as a whole: it does not fit. "
    if routed_min:
        v += ("The blocks that route " + ("reach it" if min(routed_min.values()) >= need_buf else "do not all reach it")
              + " on their own (slowest "
              + ", ".join(f"{routed_min[d]:.1f} MHz on the {DEVICES[d][0]}" for d in routed_min)
              + "). ")
    for n, sn in slow_sta:
        if 1000.0 / sn < need_buf:
            v += (f"{jobs[n]['top']} does not: its slowest register-to-register path alone takes "
                  f"{sn:.1f} ns with iCE40 HX cell delays (at most {1000.0 / sn:.1f} MHz), so on "
                  "iCE40 fabric an octave containing it cannot reach the rate on any device size "
                  "without a deeper pipeline. ")
        else:
            v += (f"{jobs[n]['top']} routed nowhere (too large for an iCE40); its slowest stage's "
                  f"logic-only bound is {1000.0 / sn:.1f} MHz, above the rate. ")
    def smallest(n):
        if (n, "xc7") not in mains:
            return None
        x = mains[(n, "xc7")][0]
        for dev in ("xc7a35t", "xc7a100t", "xc7a200t"):
            _, cl, cf, cb, cd = DEVICES[dev][:5]
            if x["lut"] <= cl and x["ff"] <= cf and x["bram"] <= cb and x["dsp"] <= cd:
                return DEVICES[dev][0]
        return "none of the listed Artix-7 parts"
    v += "On Xilinx parts this flow gives no timing; by resources the smallest listed Artix-7 for "
    v += "; ".join(f"the {jobs[n]['top']} is the {smallest(n)}" for n in ("octave0", "frontend") if smallest(n)) + "."
    A(v)
    A("")

    # ---- step log ----
    A("## Steps of this run")
    A("")
    A("| job | step | status | seconds | detail |")
    A("|---|---|---|---|---|")
    for (jn, stp), (s_, sec, det) in st.items():
        det = det.replace(out, "$SYNTH_OUT").replace("|", "/")
        if s_ == "ok":
            det = ""
        A(f"| {jn} | {stp} | {s_} | {sec} | {det} |")
    A("")
    A("Logs and netlists of the run are in `$SYNTH_OUT` (default `out/synth/`, not committed).")
    A("")

    # ---- summary at the top ----
    S = ["## Summary", ""]
    for n in ("octave0", "frontend"):
        if (n, "xc7") in mains:
            x = mains[(n, "xc7")][0]
            S.append(f"- {jobs[n]['top']} on Xilinx 7 Series (yosys): **{fmt(x['lut'])} LUT, "
                     f"{fmt(x['ff'])} FF, {fmt(x['bram'])} RAMB36, {fmt(x['dsp'])} DSP48E1**; "
                     f"smallest listed Artix-7 that holds it: {smallest(n)}.")
    if ("octave0", "ice40") in mains:
        x = mains[("octave0", "ice40")][0]
        if oct_f and oct_st and oct_st[0] == "ok":
            S.append(f"- One octave on iCE40: {fmt(x['lut'])} LUT4, {fmt(x['bram'])} SB_RAM40_4K, "
                     f"{fmt(x['dsp'])} SB_MAC16; routed on the UP5K at **{oct_f:.1f} MHz**.")
        else:
            S.append(f"- One octave on iCE40: {fmt(x['lut'])} LUT4, {fmt(x['bram'])} SB_RAM40_4K, "
                     f"{fmt(x['dsp'])} SB_MAC16: it fits neither the UP5K nor the HX8K, so no routed "
                     "Fmax for the octave; its blocks were placed and routed one by one.")
    if routed_min:
        S.append("- Slowest block of the octave, each placed and routed alone: " + ", ".join(
            f"{routed_min[d]:.1f} MHz on the {DEVICES[d][0]}" for d in routed_min)
            + f"; 640 x 240 at 60 Hz needs {need_buf:.2f} MHz.")
    for n, sn in slow_sta:
        S.append(f"- {jobs[n]['top']} fits no iCE40; its slowest stage's logic alone is {sn:.1f} ns "
                 f"(<= {1000.0 / sn:.1f} MHz) with iCE40 HX cell delays"
                 + (", below the rate needed." if 1000.0 / sn < need_buf else "."))
    if ("octave0", "xc7") in mains:
        x = mains[("octave0", "xc7")][0]
        S.append(f"- Beside Vitis Vision's DoG ({VITIS_DOG['lut']:,} LUT, {VITIS_DOG['ff']:,} FF, "
                 f"{VITIS_DOG['bram']} BRAM, {VITIS_DOG['dsp']} DSP at 1080p): one octave here is "
                 f"{fmt(x['lut'])} LUT, {fmt(x['ff'])} FF, {fmt(x['bram'])} RAMB36, {fmt(x['dsp'])} DSP. "
                 "The thesis gives no resource figures (its device: a Virtex-II of 2M gates).")
    S.append("")
    L[summary_at:summary_at] = S
    open(md_path, "w").write("\n".join(L))


if __name__ == "__main__":
    main()
