#!/usr/bin/env bash
# Synthesis report of the fabric: yosys (synth_xilinx, synth_ice40) on one octave and on the
# four-octave front end at 640 px, nextpnr-ice40 for Fmax where a design fits, and
# docs/HARDWARE.md regenerated from the numbers of this run (report.py).
#
#   bash hdl-interface/synth/run.sh            # everything (15-25 min on 2 shared cores; see the report)
#   SYNTH_ONLY="colconv cordic" bash hdl-interface/synth/run.sh   # a subset, for development
#   bash hdl-interface/synth/run.sh --report-only   # docs/HARDWARE.md again from the last run's logs
#
# Environment:
#   SYNTH_OUT      scratch directory for logs and netlists (default: <repo>/out/synth, ignored
#                  by git; wiped at the start of a full run)
#   SYNTH_TIMEOUT  seconds per yosys step (default 1500); PNR_TIMEOUT per nextpnr run (600)
#   SYNTH_ONLY     space-separated job names (see JOBS below); the report then covers them only
#   SYNTH_JOBS     parallel jobs (default 2)
#   NO_REPORT=1    do not rewrite docs/HARDWARE.md
#
# Every step runs under `timeout`; its outcome (ok / timeout / error / skipped and why) goes to
# $SYNTH_OUT/status.tsv, which the report prints, so a step that timed out or failed is named in
# docs/HARDWARE.md instead of vanishing.
set -u

HERE=$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)
REPO=$(cd "$HERE/../.." && pwd)
RTL=$REPO/hdl-interface/rtl
OUT=${SYNTH_OUT:-$REPO/out/synth}
SYNTH_TIMEOUT=${SYNTH_TIMEOUT:-1500}
PNR_TIMEOUT=${PNR_TIMEOUT:-600}
PAR=${SYNTH_JOBS:-2}
PNR_FREQ=50   # nextpnr target (MHz); the achieved Fmax is reported whatever the target

if [ "${1:-}" = --report-only ]; then
    # Rewrite docs/HARDWARE.md from the logs of the last run in $SYNTH_OUT.
    exec python3 "$HERE/report.py" "$OUT" "$REPO/docs/HARDWARE.md"
fi

for tool in yosys nextpnr-ice40 python3 timeout; do
    command -v "$tool" >/dev/null || { echo "run.sh: $tool not found" >&2; exit 1; }
done

# name | top module | parameters | nextpnr devices ("-" = none; "xc7" = 7 Series only) | what it is
# The first two are the report's subject; the others are the blocks of one octave, placed and
# routed on their own for an Fmax figure where the octave does not fit an iCE40.
JOBS=(
  "octave0|sc_octave|W=640 INDEX=0|up5k|one octave, octave 0 (with the input filter G0), 640 px lines"
  "frontend|sc_frontend|W0=640 W1=320 W2=160 W3=80|-|the front end: four octaves, 640/320/160/80 px lines"
  "rowconv|sc_row_conv||up5k hx8k|row convolver (5-tap DA dot product)"
  "colconv|sc_col_conv|W=640|up5k hx8k|column convolver, 4 line memories of 640"
  "window48|sc_window3|DW=48 W=640|up5k hx8k|3x3 DoG window former (3 x i16 per element), 640 px"
  "alignfifo|sc_line_fifo|DW=16 DEPTH=4480|up5k hx8k|alignment FIFO of G0 (7 lines of 640)"
  "extrema|sc_extrema||up5k hx8k|26-neighbour extremum test (combinational, registered I/O)"
  "edge|sc_edge||up5k hx8k|edge (Hessian ratio) test (combinational, registered I/O)"
  "refine|sc_refine||up5k hx8k|sub-pixel refinement (combinational, registered I/O)"
  "sobel|sc_sobel||up5k hx8k|3x3 Sobel (combinational, registered I/O)"
  "cordic|sc_cordic||up5k hx8k|CORDIC magnitude/orientation pipeline"
  "stream|sc_stream|W0=640|xc7|the stream engine: snapshot queue, 68-row ring, stash, patch queue, batch, packet former, framer; 640 px rows"
)

if [ -z "${SYNTH_ONLY:-}" ]; then
    rm -rf "$OUT"
fi
mkdir -p "$OUT"
STATUS=$OUT/status.tsv
[ -f "$STATUS" ] || printf 'job\tstep\tstatus\tseconds\tdetail\n' > "$STATUS"
T0=$(date +%s)
if [ -z "${SYNTH_ONLY:-}" ] || [ ! -f "$OUT/started" ]; then
    date -u +%Y-%m-%dT%H:%M:%SZ > "$OUT/started"
    cut -d' ' -f1-3 /proc/loadavg > "$OUT/load_start" 2>/dev/null
    git -C "$REPO" rev-parse --short HEAD > "$OUT/rtl_commit" 2>/dev/null
    git -C "$REPO" status --porcelain -- hdl-interface/rtl > "$OUT/rtl_dirty" 2>/dev/null
    RERUN=
else
    # A subset on top of an earlier run: its jobs' results replace theirs, and the report
    # says which jobs were re-run when, from which RTL.
    RERUN="$(date -u +%Y-%m-%dT%H:%M:%SZ) $(git -C "$REPO" rev-parse --short HEAD 2>/dev/null) $SYNTH_ONLY"
fi

# status JOB STEP STATUS SECONDS DETAIL (one line, appended atomically enough for 2 writers)
status() { printf '%s\t%s\t%s\t%s\t%s\n' "$1" "$2" "$3" "$4" "$5" >> "$STATUS"; }

# run_step JOB STEP TIMEOUT LOG cmd... : runs cmd under timeout, records the outcome.
run_step() {
    local job=$1 step=$2 tmo=$3 log=$4; shift 4
    local t=$(date +%s) rc
    timeout "$tmo" "$@" > "$log.out" 2>&1
    rc=$?
    local dt=$(( $(date +%s) - t ))
    if [ $rc -eq 0 ]; then
        status "$job" "$step" ok "$dt" "$log"
    elif [ $rc -eq 124 ]; then
        status "$job" "$step" timeout "$dt" "timed out after ${tmo} s ($log)"
    else
        local msg
        msg=$(grep -m1 -E '^ERROR|ERROR:|error:' "$log" "$log.out" 2>/dev/null | head -1 | cut -c1-300 | tr '\t' ' ')
        status "$job" "$step" "error" "$dt" "rc=$rc: ${msg:-see $log}"
    fi
    return $rc
}

# Files of TOP and of every sc_ module it instantiates (transitively), or "MISSING:<module>".
deps() {
    python3 - "$RTL" "$1" <<'EOF'
import os, re, sys
rtl, top = sys.argv[1], sys.argv[2]
seen, todo, files, missing = set(), [top], [], []
inst = re.compile(r'^\s*(sc_\w+)\s*(?:#\s*\(|\w+\s*\()', re.M)
while todo:
    m = todo.pop()
    if m in seen:
        continue
    seen.add(m)
    f = os.path.join(rtl, m + '.v')
    if not os.path.exists(f):
        missing.append(m)
        continue
    files.append(f)
    src = re.sub(r'//.*', '', open(f).read())
    src = re.sub(r'/\*.*?\*/', '', src, flags=re.S)
    for n in inst.findall(src):
        if n != m and n not in seen:
            todo.append(n)
print(' '.join(files) if not missing else 'MISSING:' + ','.join(sorted(missing)))
EOF
}

# chparam arguments from "A=1 B=2"
chparams() {
    local s="" kv
    for kv in $1; do s="$s -set ${kv%%=*} ${kv#*=}"; done
    echo "$s"
}

do_job() {
    local spec=$1
    local name top params devs what
    IFS='|' read -r name top params devs what <<< "$spec"
    local d=$OUT/$name
    mkdir -p "$d"
    printf '%s\n%s\n%s\n%s\n%s\n' "$name" "$top" "$params" "$devs" "$what" > "$d/job.txt"
    local files
    files=$(deps "$top")
    if [[ $files == MISSING:* ]]; then
        status "$name" deps skipped "0" "module file(s) not in hdl-interface/rtl: ${files#MISSING:}"
        return
    fi
    echo "$files" > "$d/files.txt"
    local cp=""
    [ -n "$params" ] && cp="chparam $(chparams "$params") $top;"
    local rd="read_verilog -defer $files;"

    # Xilinx 7-series (octave, front end and stream engine; the blocks only go to the iCE40):
    # hierarchy kept, so the report can break the totals down per block.
    if [ "$name" = octave0 ] || [ "$name" = frontend ] || [ "$devs" = xc7 ]; then
        run_step "$name" xc7 "$SYNTH_TIMEOUT" "$d/xc7.log" \
            yosys -q -l "$d/xc7.log" -p "$rd $cp synth_xilinx -family xc7 -noiopad -top $top; tee -q -o $d/xc7.stat.json stat -json"
    fi

    # Virtex-II (the thesis' family, yosys support marked experimental), the octave only: it
    # already exceeds the thesis' XC2V2000 alone, and this step is the slowest of the run.
    if [ "$name" = octave0 ]; then
        run_step "$name" xc2v "$SYNTH_TIMEOUT" "$d/xc2v.log" \
            yosys -q -l "$d/xc2v.log" -p "$rd $cp synth_xilinx -family xc2v -noiopad -top $top; tee -q -o $d/xc2v.stat.json stat -json"
    fi

    # The stream engine's memories (its row ring alone is 609 Kbit at 640 px) fit no iCE40's
    # block RAM: yosys maps them to logic cells there and does not finish in SYNTH_TIMEOUT.
    # The framer is reported inside the engine.
    if [ "$devs" = xc7 ]; then
        status "$name" ice40 skipped 0 "memories beyond any iCE40's block RAM: 7 Series only"
        return
    fi

    # iCE40 (UltraPlus primitives, SB_MAC16 allowed). With a place-and-route device the module
    # sits in the three-pin shell (shell.py); the module stays a hierarchy level of its own.
    if [ "$devs" = "-" ]; then
        run_step "$name" ice40 "$SYNTH_TIMEOUT" "$d/ice40.log" \
            yosys -q -l "$d/ice40.log" -p "$rd $cp synth_ice40 -dsp -noflatten -top $top; tee -q -o $d/ice40.stat.json stat -json"
        return
    fi
    run_step "$name" ports "$SYNTH_TIMEOUT" "$d/ports.log" \
        yosys -q -l "$d/ports.log" -p "$rd $cp hierarchy -top $top; proc; write_json $d/ports.json" || return
    python3 "$HERE/shell.py" "$d/ports.json" "$top" "$params" "$d/shell.v" > "$d/shell.txt" 2>&1 \
        || { status "$name" shell error 0 "shell.py failed: $(tail -1 "$d/shell.txt")"; return; }
    run_step "$name" ice40 "$SYNTH_TIMEOUT" "$d/ice40.log" \
        yosys -q -l "$d/ice40.log" -p "read_verilog -defer $files $d/shell.v; hierarchy -top sc_synth_shell; synth_ice40 -dsp -noflatten -top sc_synth_shell; tee -q -o $d/ice40.stat.json stat -json; flatten; write_json $d/up5k.net.json" \
        || return
    local dev
    for dev in $devs; do
        local net=$d/up5k.net.json pkg=sg48
        if [ "$dev" = hx8k ]; then
            # No DSP on the HX parts: synthesise again without SB_MAC16.
            pkg=ct256
            net=$d/hx8k.net.json
            run_step "$name" ice40-hx "$SYNTH_TIMEOUT" "$d/ice40hx.log" \
                yosys -q -l "$d/ice40hx.log" -p "read_verilog -defer $files $d/shell.v; hierarchy -top sc_synth_shell; synth_ice40 -top sc_synth_shell; tee -q -o $d/ice40hx.stat.json stat -json; write_json $net" \
                || continue
            # Logic-only critical path with the HX cell delays of yosys' iCE40 library (no
            # routing): a bound that exists even when the block does not fit a device.
            run_step "$name" sta-hx "$SYNTH_TIMEOUT" "$d/sta-hx.log" \
                yosys -q -l "$d/sta-hx.log" -p "read_json $net; read_verilog -D ICE40_HX -lib -specify +/ice40/cells_sim.v; sta"
        fi
        run_step "$name" "pnr-$dev" "$PNR_TIMEOUT" "$d/pnr-$dev.log" \
            nextpnr-ice40 "--$dev" --package "$pkg" --json "$net" --pcf-allow-unconstrained \
                --freq "$PNR_FREQ" --timing-allow-fail --seed 1 \
                --report "$d/pnr-$dev.report.json" -l "$d/pnr-$dev.log" -q
    done
}

export -f do_job run_step status deps chparams
export OUT RTL HERE STATUS SYNTH_TIMEOUT PNR_TIMEOUT PNR_FREQ

sel=()
for spec in "${JOBS[@]}"; do
    name=${spec%%|*}
    if [ -z "${SYNTH_ONLY:-}" ] || [[ " $SYNTH_ONLY " == *" $name "* ]]; then
        sel+=("$spec")
    fi
done
echo "run.sh: ${#sel[@]} jobs, $PAR in parallel, logs in $OUT"
# do_job's status is in status.tsv; exit 0 so that xargs never stops on a failed step.
printf '%s\0' "${sel[@]}" | xargs -0 -P "$PAR" -I{} bash -c 'do_job "$1"; exit 0' _ {}

T1=$(date +%s)
if [ -n "$RERUN" ]; then
    echo "$RERUN $(( T1 - T0 ))" >> "$OUT/reruns"
else
    echo $(( T1 - T0 )) > "$OUT/seconds"
    cut -d' ' -f1-3 /proc/loadavg > "$OUT/load_end" 2>/dev/null
fi
echo "run.sh: done in $(( T1 - T0 )) s"
column -t -s $'\t' "$STATUS" | cut -c1-160

if [ -z "${NO_REPORT:-}" ]; then
    python3 "$HERE/report.py" "$OUT" "$REPO/docs/HARDWARE.md" && echo "run.sh: wrote docs/HARDWARE.md"
fi
