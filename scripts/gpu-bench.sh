#!/usr/bin/env bash
# The GPU backend (device=cuda, issue 42) on a machine with an NVIDIA GPU, in one go:
#
#   scripts/gpu-bench.sh [OUT_DIR]      (default OUT_DIR: gpu-bench-out)
#
# 1. nvidia-smi and the CUDA libraries numba-cuda finds;
# 2. the GPU correctness tests (tests/gpu/test_gpu_simulator.py) on the GPU itself, not the simulator;
# 3. the quick preset's warping tasks with device=cuda and with device=cpu (workers = all cores), render
#    caches warmed first: fig. 5.6's 2D-warping cross-database task 0 of 16 and a min-warping grid run of
#    six snapshots; per command the wall time, the process CPU time and the run's own pair time
#    (metrics.json: ms_per_home_vector), as JSON lines in OUT_DIR/gpu-bench.jsonl; and each GPU run's
#    results against the CPU run's (cross_db.csv / metrics.json) as a diff.
#
# Needs the repository's checkout and Python >= 3.11; installs bionav with the gpu extra into a fresh venv in
# OUT_DIR/venv (numba-cuda with the CUDA 12 toolkit from PyPI; the driver comes with the machine). Prints what it
# runs; stops at the first failure (set -e). Runs nothing on the CPU alone if no GPU is found.
set -euo pipefail

OUT="${1:-gpu-bench-out}"
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
mkdir -p "$OUT"
OUT="$(cd "$OUT" && pwd)"
LOG="$OUT/gpu-bench.jsonl"
: > "$LOG"

command -v nvidia-smi >/dev/null || { echo "gpu-bench: no nvidia-smi here: this script needs an NVIDIA GPU" >&2; exit 3; }
nvidia-smi --query-gpu=name,driver_version,memory.total --format=csv | tee "$OUT/nvidia-smi.csv"

if [ ! -x "$OUT/venv/bin/python" ]; then
  python3 -m venv "$OUT/venv"
  "$OUT/venv/bin/pip" install -q -e "$ROOT[test,gpu]"
fi
PY="$OUT/venv/bin/python"
"$PY" -c "from numba import cuda; cuda.detect()"

# 2. correctness on the device
(cd "$ROOT" && BIONAV_GPU_DEVICE_TESTS=1 "$PY" -m pytest tests/gpu -q)

# 3. timings
export BIONAV_CACHE="${BIONAV_CACHE:-$OUT/cache}"
CORES="$("$PY" -c 'from bionav.machine import usable_cpus; print(usable_cpus())')"
FAMILY='experiment.family=[sim_original,sim_arboreal,sim_chairs,sim_doorlit,sim_screen,sim_winlit]'
CROSS=(experiment=cross_db homing=warping2d "$FAMILY" experiment.snapshot_stride=9 'db.image_size=[346,50]'
       'experiment.block=[0,16]')
GRID=(experiment=grid_homing db=sim_hall1 homing=minwarping 'experiment.snapshots=[0,34,68,101,135,169]')

timed() {  # name device args...: one JSON line with wall, CPU and the run's ms_per_home_vector
  local name="$1" device="$2"; shift 2
  local dir="$OUT/runs/$name-$device"
  rm -rf "$dir"
  local t0; t0="$(date +%s.%N)"
  /usr/bin/time -f "%U %S" -o "$OUT/time.txt" "$PY" -m bionav "$@" "device=$device" "workers=$CORES" \
      "hydra.run.dir=$dir" > "$OUT/$name-$device.log" 2>&1
  local t1; t1="$(date +%s.%N)"
  "$PY" - "$name" "$device" "$t0" "$t1" "$OUT/time.txt" "$dir/metrics.json" "$CORES" >> "$LOG" <<'EOF'
import json, sys
name, device, t0, t1, tfile, mfile, cores = sys.argv[1:]
user, system = map(float, open(tfile).read().split()[-2:])
m = json.load(open(mfile))
print(json.dumps({"task": name, "device": device, "workers": int(cores), "wall_s": round(float(t1) - float(t0), 2),
                  "cpu_s": round(user + system, 2), "ms_per_home_vector": m.get("ms_per_home_vector"),
                  "n_pairs": m.get("n_pairs"), "status": m.get("status")}))
EOF
  tail -1 "$LOG"
}

"$PY" -m bionav "${CROSS[@]}" device=cpu "hydra.run.dir=$OUT/runs/warm-cross" > /dev/null 2>&1  # renders, compiles
"$PY" -m bionav "${GRID[@]}" device=cpu "hydra.run.dir=$OUT/runs/warm-grid" > /dev/null 2>&1
for device in cuda cpu cuda; do
  timed cross_db_warping2d_block0 "$device" "${CROSS[@]}"
  timed grid_minwarping_hall1 "$device" "${GRID[@]}"
done
diff "$OUT/runs/cross_db_warping2d_block0-cuda/cross_db.csv" "$OUT/runs/cross_db_warping2d_block0-cpu/cross_db.csv" \
  && echo "cross_db.csv: GPU = CPU" || echo "cross_db.csv differs (see the tolerance in bionav/gpu/warp2d.py)"
"$PY" - "$OUT/runs" <<'EOF'
import json, sys
from pathlib import Path
runs = Path(sys.argv[1])
a = json.loads((runs / "grid_minwarping_hall1-cuda" / "metrics.json").read_text())
b = json.loads((runs / "grid_minwarping_hall1-cpu" / "metrics.json").read_text())
print("grid min-warping AAE / RR, GPU vs CPU:", a.get("aae"), b.get("aae"), a.get("rr"), b.get("rr"))
EOF
echo "gpu-bench: results in $LOG"
