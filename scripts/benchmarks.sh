#!/usr/bin/env bash
# Regenerates the main table of BENCHMARKS.md: the reference scenes, Kantele's CPU backend
# against OpenGL (llvmpipe), as Markdown ready to paste, with its machine, command and date.
#
# Usage: scripts/benchmarks.sh [KANTELE [SCENES_DIR [ROUNDS]]]
#   KANTELE     the kantele binary, built with the OpenGL yardstick
#               (cargo build --release -p kantele-cli --features gl); default target/release/kantele
#   SCENES_DIR  the reference scenes (every *.glb in it); default $KANTELE_SHARED/scenes, where
#               KANTELE_SHARED defaults to ../shared beside the repository
#   ROUNDS      rounds of `kantele bench`, the order of the two backends alternating (default 3)
# Environment:
#   FRAMES      timed frames per scene, backend and round (default 30)
#   THREADS     Kantele's worker threads and llvmpipe's LP_NUM_THREADS (default: every CPU)
#   MSAA        samples per pixel for both renderers (`--msaa`; default 1)
#   STAGES      when set, a second table: Kantele's stage times and fragments shaded per scene
#
# The llvmpipe measured is the Mesa that the process's libEGL loads. To measure a particular
# Mesa build, source the env.sh that the Mesa unpack tool writes into its folder first:
#   . MESA_DIR/env.sh; scripts/benchmarks.sh
# Run it on an otherwise idle machine. Each figure is the median over the rounds of each
# round's median frame; the last column is the range of the per-round ratios.
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
kantele=${1:-$root/target/release/kantele}
shared=${KANTELE_SHARED:-$root/../shared}
scenes_dir=${2:-$shared/scenes}
rounds=${3:-3}
frames=${FRAMES:-30}

if [[ ! -x $kantele ]]; then
    echo "benchmarks: no kantele binary at $kantele;" \
        "build it: cargo build --release -p kantele-cli --features gl" >&2
    exit 1
fi
shopt -s nullglob
scenes=("$scenes_dir"/*.glb)
shopt -u nullglob
if (( ${#scenes[@]} == 0 )); then
    echo "benchmarks: no .glb scenes in $scenes_dir (set KANTELE_SHARED or pass SCENES_DIR)" >&2
    exit 1
fi
if ! [[ $rounds =~ ^[1-9][0-9]*$ && $frames =~ ^[1-9][0-9]*$ ]]; then
    echo "benchmarks: ROUNDS and FRAMES must be positive integers" >&2
    exit 1
fi
thread_args=()
if [[ -n ${THREADS:-} ]]; then
    thread_args=(--threads "$THREADS")
    export LP_NUM_THREADS=$THREADS
fi
if [[ -n ${MSAA:-} ]]; then
    if ! [[ $MSAA =~ ^[1-9][0-9]*$ ]]; then
        echo "benchmarks: MSAA must be a positive integer" >&2
        exit 1
    fi
    thread_args+=(--msaa "$MSAA")
fi

work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

# Each round writes to a file, not a pipe: a reader running beside the frames would take a CPU.
for ((r = 1; r <= rounds; r++)); do
    if (( r % 2 )); then order=cpu,gl; else order=gl,cpu; fi
    echo "benchmarks: round $r of $rounds (--backends $order)" >&2
    "$kantele" bench "${scenes[@]}" --backends "$order" --frames "$frames" \
        ${thread_args[@]+"${thread_args[@]}"} --json >"$work/round-$r.json"
done

model=$(sed -n 's/^model name[[:space:]]*:[[:space:]]*//p' /proc/cpuinfo 2>/dev/null | head -n 1)
memory=$(awk '/^MemTotal:/ { printf "%.0f GiB", $2 / 1048576 }' /proc/meminfo 2>/dev/null || true)

MODEL=${model:-unknown CPU} CPUS=$(nproc) MEMORY=${memory:-unknown memory} \
KERNEL="$(uname -s) $(uname -r)" DATE=$(date -u +%Y-%m-%d) ROUNDS=$rounds FRAMES=$frames \
SCENE_COUNT=${#scenes[@]} THREADS_ARG=${THREADS:-} MSAA_ARG=${MSAA:-} STAGES=${STAGES:-} \
python3 - "$work"/round-*.json <<'PY'
import json
import math
import os
import statistics
import sys

medians = {}  # (scene, backend) -> {round: median ms}
stages = {}   # scene -> [(geometry, binning, raster, fragments shaded)] of Kantele's rounds
info = {}     # scene -> (width, height, triangles)
about = {}    # backend -> the first available row
errors = {}
order = []
for round_index, path in enumerate(sys.argv[1:]):
    with open(path) as f:
        for line in f:
            line = line.strip()
            if not line.startswith("{"):
                continue
            row = json.loads(line)
            scene, backend = row["scene"], row["backend"]
            if scene not in info:
                order.append(scene)
                info[scene] = (row["width"], row["height"], row["triangles"])
            if row.get("available") and row.get("median_ms") is not None:
                medians.setdefault((scene, backend), {})[round_index] = row["median_ms"]
                if backend == "cpu" and row.get("geometry_ms") is not None:
                    stages.setdefault(scene, []).append((row["geometry_ms"], row["binning_ms"],
                                                         row["raster_ms"], row["fragments_shaded"]))
                about.setdefault(backend, row)
            else:
                errors.setdefault(backend, row.get("error") or "unavailable")

for backend in ("cpu", "gl"):
    if backend not in about:
        why = errors.get(backend, "no result")
        sys.exit(f"benchmarks: the {backend} backend rendered nothing: {why}")

def group(n):
    return f"{n:,}".replace(",", " ")

env = os.environ
cpu, gl = about["cpu"], about["gl"]
threads = env["THREADS_ARG"]
threads_arg = f" --threads {threads}" if threads else ""
if env["MSAA_ARG"]:
    threads_arg += f" --msaa {env['MSAA_ARG']}"
print(f"Machine: {env['MODEL']}, {env['CPUS']} CPUs, {env['MEMORY']}, {env['KERNEL']}.")
print(f"Kantele: {cpu['build']}, {cpu['threads']} worker threads, isa `{cpu['isa']}`, "
      f"target `{cpu['target']}`; llvmpipe: {gl['renderer']}, target `{gl['target']}`.")
print(f"Measured {env['DATE']}.")
print(f"Command: `scripts/benchmarks.sh`: {env['ROUNDS']} rounds of `kantele bench "
      f"<{env['SCENE_COUNT']} scenes> --backends cpu,gl --frames {env['FRAMES']}{threads_arg} "
      f"--json`, the backends' order alternating; medians over the rounds.")
print()
print("| scene | size | triangles | Kantele ms | llvmpipe ms | llvmpipe / Kantele | per round |")
print("|---|---|---:|---:|---:|---:|---:|")
logs = []
for scene in order:
    width, height, triangles = info[scene]
    k = medians.get((scene, "cpu"), {})
    g = medians.get((scene, "gl"), {})
    if not k or not g:
        print(f"| {scene} | {width}x{height} | {group(triangles)} | - | - | - | |")
        continue
    km, gm = statistics.median(k.values()), statistics.median(g.values())
    ratio = gm / km
    logs.append(math.log(ratio))
    per_round = [g[r] / k[r] for r in sorted(k) if r in g]
    spread = f"{min(per_round):.2f}–{max(per_round):.2f}" if len(per_round) > 1 else ""
    print(f"| {scene} | {width}x{height} | {group(triangles)} | {km:.3f} | {gm:.3f} "
          f"| {ratio:.2f} | {spread} |")
if logs:
    mean = math.exp(sum(logs) / len(logs))
    print(f"| **geometric mean** | | | | | **{mean:.2f}** | |")
if stages and os.environ.get("STAGES"):
    print()
    print("Kantele's stages, median ms over the rounds:")
    print()
    print("| scene | geometry | binning | raster | fragments shaded |")
    print("|---|---:|---:|---:|---:|")
    for scene in order:
        if scene in stages:
            rows = stages[scene]
            g, b, r = (statistics.median(row[k] for row in rows) for k in range(3))
            print(f"| {scene} | {g:.3f} | {b:.3f} | {r:.3f} | {group(rows[-1][3])} |")
PY
