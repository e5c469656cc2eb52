#!/usr/bin/env bash
# Fetches the SoC's soft-core and adapts it to the memory map of QEMU's `virt` machine.
#
#   bash hdl-interface/soc/fetch_core.sh OUTDIR     # writes OUTDIR/VexRiscv_virt.v
#
# The core is VexRiscv, variant IMAC (RV32IMAC, the CSRs riscv-rt writes, mcycle/minstret,
# 4 KiB instruction and data caches, Wishbone instruction and data buses; MIT licence), as
# LiteX publishes it on PyPI: pythondata-cpu-vexriscv, pinned below, installed into a venv of
# OUTDIR's own. Nothing of it is kept in the repository.
#
# The one edit: the generated core treats addresses with bit 31 set as I/O (uncached, never
# speculated), LiteX's map with RAM low. QEMU's `virt`, whose map the firmware ELF is linked
# for, has RAM at 0x8000_0000 and the UART, the finisher and the fabric below it; there bit 31
# CLEAR must be I/O, or the fabric's pop-on-read registers would be cached and RAM would be
# slow. The two assigns that decide it (instruction and data side) are inverted, and the script
# fails unless it finds exactly those two.
set -euo pipefail

OUT=${1:?usage: fetch_core.sh OUTDIR}
PKG=pythondata-cpu-vexriscv==1.0.1.post407
VARIANT=VexRiscv_IMAC.v

mkdir -p "$OUT"
if [ ! -x "$OUT/venv/bin/python" ]; then
    python3 -m venv "$OUT/venv"
fi
"$OUT/venv/bin/pip" install --quiet --disable-pip-version-check "$PKG"
SRC=$("$OUT/venv/bin/python" -c \
    'import os, pythondata_cpu_vexriscv as p; print(os.path.join(p.data_location, "'$VARIANT'"))')

TMP=$OUT/VexRiscv_virt.v.tmp
python3 - "$SRC" "$TMP" <<'PY'
import re, sys
src, dst = sys.argv[1], sys.argv[2]
text = open(src).read()
pattern = re.compile(
    r"assign (IBusCachedPlugin|DBusCachedPlugin)_mmuBus_rsp_isIoAccess = "
    r"\1_mmuBus_rsp_physicalAddress\[31\];")
text, n = pattern.subn(
    lambda m: f"assign {m.group(1)}_mmuBus_rsp_isIoAccess = "
              f"!{m.group(1)}_mmuBus_rsp_physicalAddress[31];", text)
if n != 2:
    sys.exit(f"fetch_core.sh: expected the 2 isIoAccess assigns in {src}, found {n}")
open(dst, "w").write(
    "// VexRiscv_IMAC from PyPI pythondata-cpu-vexriscv 1.0.1.post407 (MIT), with the I/O\n"
    "// region inverted for QEMU virt's memory map by hdl-interface/soc/fetch_core.sh.\n" + text)
PY
mv "$TMP" "$OUT/VexRiscv_virt.v"
echo "fetch_core.sh: $OUT/VexRiscv_virt.v"
