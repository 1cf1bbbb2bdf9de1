#!/usr/bin/env bash
# The CUDA backend's check, for a machine with an NVIDIA GPU (CI has none): run it after changing
# the kernels.
#
#   crates/kantele-cuda/gpu-check.sh build [DIR]
#       builds the release binary with --features cuda and puts it, stripped, into DIR (default
#       target/gpu-check) with the reference scenes and this script (about 30 MB), for a GPU
#       machine without a Rust toolchain: copy DIR there and run DIR/gpu-check.sh run.
#   crates/kantele-cuda/gpu-check.sh run [KANTELE [OUT]]
#       every check below. KANTELE: the kantele binary built with --features cuda (default
#       $KANTELE, else the kantele beside this script, else target/gpu-check/kantele, else
#       target/release/kantele); OUT: the folder for logs, pictures and summary.txt (default
#       $OUT, else gpu-check-out in the current folder).
#
# The reference scenes are $KANTELE_SHARED/scenes (KANTELE_SHARED defaults to ../shared beside
# the checkout; see docs/rendering-rules.md, "Reference scenes"); without KANTELE_SHARED, `run`
# takes the scenes/ folder beside the binary when there is one (as `build` lays it out).
#
# What `run` checks, each step logged to its own file and summarised in summary.txt:
#  1. the device, the driver and where NVRTC comes from (KANTELE_NVRTC, else the CUDA toolkit,
#     else the nvidia-cuda-nvrtc wheel of the machine's Python);
#  2. every reference scene and built-in: `kantele compare --backends cpu,cuda` with zero
#     coverage difference allowed, and the window depth of cpu and cuda compared byte for byte;
#     the same for the two thesis baselines (cuda-ocot, cuda-ocmt) on the small scenes;
#  3. ten repeated cuda renders of three scenes: byte-identical PNGs and depth files;
#  4. compute-sanitizer memcheck and racecheck on one render (it refuses the GPU on some
#     machines: that is logged, not hidden);
#  5. `kantele bench` of every scene with cpu, cuda, cuda-ocot, cuda-ocmt and gl;
#  6. the CPU backend's thread scaling: every scene at 1, 2, 4, 8 and 16 threads (`--json`, one
#     file per count: scaling-N.json), with the 16 / 1 ratios in scaling.log.
# The script goes on after a failing step and exits non-zero if any step failed.
set -uo pipefail
self="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$self/../.." && pwd)"

# The reference scenes' folder for `build`: $KANTELE_SHARED/scenes, else ../shared/scenes.
shared_scenes() {
  echo "${KANTELE_SHARED:-$root/../shared}/scenes"
}

build() {
  set -e
  local bundle="${1:-$root/target/gpu-check}"
  local scenes
  scenes="$(shared_scenes)"
  if ! ls "$scenes"/*.glb >/dev/null 2>&1; then
    echo "error: no reference scenes in $scenes (set KANTELE_SHARED)" >&2
    exit 2
  fi
  scenes="$(cd "$scenes" && pwd)"
  mkdir -p "$bundle/scenes"
  bundle="$(cd "$bundle" && pwd)"
  cd "$root"
  cargo build --release --locked -p kantele-cli --features cuda
  strip -o "$bundle/kantele" target/release/kantele
  cp "$scenes"/*.glb "$bundle/scenes/"
  cp "$self/gpu-check.sh" "$bundle/gpu-check.sh"
  du -sh "$bundle"
  echo "ready: copy $bundle to the GPU machine and run: $bundle/gpu-check.sh run"
}

find_nvrtc() {
  if [ -n "${KANTELE_NVRTC:-}" ]; then echo "$KANTELE_NVRTC"; return; fi
  for f in /usr/local/cuda/lib64/libnvrtc.so.13 /usr/local/cuda-13.0/lib64/libnvrtc.so.13 \
           /usr/local/cuda/targets/x86_64-linux/lib/libnvrtc.so.13; do
    [ -f "$f" ] && { echo "$f"; return; }
  done
  local site
  site="$(python3 -c 'import nvidia, os; print(os.path.dirname(nvidia.__path__[0]))' 2>/dev/null)"
  for f in "$site"/nvidia/cu13/lib/libnvrtc.so.13 "$site"/nvidia/cuda_nvrtc/lib/libnvrtc.so.13; do
    [ -f "$f" ] && { echo "$f"; return; }
  done
  ldconfig -p 2>/dev/null | awk '/libnvrtc.so.13 /{print $NF; exit}'
}

run() {
  local k="${1:-${KANTELE:-}}" out="${2:-${OUT:-gpu-check-out}}" scenes failed=0
  if [ -z "$k" ]; then
    for k in "$self/kantele" "$root/target/gpu-check/kantele" "$root/target/release/kantele"; do
      [ -x "$k" ] && break
    done
  fi
  if [ ! -x "$k" ]; then
    echo "error: no kantele binary at $k (give it: $0 run KANTELE [OUT])" >&2
    return 2
  fi
  if [ -n "${KANTELE_SHARED:-}" ]; then
    scenes="$KANTELE_SHARED/scenes"
  elif [ -d "$(dirname "$k")/scenes" ]; then
    scenes="$(dirname "$k")/scenes"
  else
    scenes="$(shared_scenes)"
  fi
  if ! ls "$scenes"/*.glb >/dev/null 2>&1; then
    echo "error: no reference scenes in $scenes (set KANTELE_SHARED)" >&2
    return 2
  fi
  mkdir -p "$out"
  out="$(cd "$out" && pwd)"
  local summary="$out/summary.txt"
  : >"$summary"
  step() { # name, command...
    local name="$1"; shift
    local start=$SECONDS
    if "$@" >"$out/$name.log" 2>&1; then
      echo "PASS $name ($((SECONDS - start)) s)" | tee -a "$summary"
    else
      echo "FAIL $name ($((SECONDS - start)) s): see $name.log" | tee -a "$summary"
      tail -5 "$out/$name.log" | sed 's/^/    /' | tee -a "$summary"
      failed=1
    fi
  }
  export KANTELE_NVRTC="$(find_nvrtc)"
  export KANTELE_CUDA_CACHE="$out/ptx-cache"
  {
    nvidia-smi -L; nvidia-smi --query-gpu=driver_version,name --format=csv
    echo "NVRTC: ${KANTELE_NVRTC:-not found}"
    "$k" --version
  } >"$out/device.log" 2>&1
  cat "$out/device.log" | tee -a "$summary"

  local all=("$scenes"/*.glb)
  local builtins=(cube teapot ground pixel-edges)
  compare_exact() { # scene args..., backend
    local b="$1"; shift
    "$k" compare "$@" --backends "cpu,$b" --max-coverage-diff 0 --out "$out/compare-$b"
  }
  depth_identical() { # scene-file-or-builtin backend
    local s="$1" b="$2" name
    name="$(basename "$s" .glb)"
    local src=("$s"); [ -f "$s" ] || src=(--builtin "$s")
    "$k" render "${src[@]}" --backend cpu -o "$out/d/$name-cpu.png" --depth "$out/d/$name-cpu.pfm" \
      --depth-kind window &&
      "$k" render "${src[@]}" --backend "$b" -o "$out/d/$name-$b.png" \
        --depth "$out/d/$name-$b.pfm" --depth-kind window &&
      cmp "$out/d/$name-cpu.pfm" "$out/d/$name-$b.pfm" && echo "$name: depth identical ($b)"
  }
  mkdir -p "$out/d"
  step compare-cuda compare_exact cuda "${all[@]}" $(printf -- '--builtin %s ' "${builtins[@]}")
  depth_all() {
    local s r=0
    for s in "${all[@]}" "${builtins[@]}"; do depth_identical "$s" cuda || r=1; done
    return $r
  }
  step depth-cuda depth_all
  local small=("$scenes"/thesis-cube-textured.glb "$scenes"/near-clip.glb "$scenes"/alpha-blend.glb
    "$scenes"/thesis-t1-b2f-10.glb "$scenes"/paper-c1-lowpoly-far.glb)
  step compare-ocot compare_exact cuda-ocot "${small[@]}" --builtin pixel-edges
  step compare-ocmt compare_exact cuda-ocmt "${small[@]}" --builtin pixel-edges

  repeat_identical() {
    local s name i r=0
    for s in "$scenes"/bunny.glb "$scenes"/alpha-blend.glb "$scenes"/spot-textured.glb; do
      name="$(basename "$s" .glb)"
      for i in $(seq 1 10); do
        "$k" render "$s" --backend cuda -o "$out/rep/$name-$i.png" --depth "$out/rep/$name-$i.pfm" \
          --depth-kind window >/dev/null || return 1
      done
      local png pfm
      png="$(md5sum "$out/rep/$name"-*.png | awk '{print $1}' | sort -u | wc -l)"
      pfm="$(md5sum "$out/rep/$name"-*.pfm | awk '{print $1}' | sort -u | wc -l)"
      echo "$name: $png distinct PNGs, $pfm distinct depth files in 10 renders"
      [ "$png" = 1 ] && [ "$pfm" = 1 ] || r=1
    done
    return $r
  }
  mkdir -p "$out/rep"
  step repeat-10 repeat_identical

  if command -v compute-sanitizer >/dev/null; then
    local cs=(compute-sanitizer --error-exitcode 9)
    step memcheck "${cs[@]}" --tool memcheck "$k" render "$scenes"/spot-textured.glb --backend cuda \
      -o "$out/memcheck.png" --size 320x240
    step racecheck "${cs[@]}" --tool racecheck "$k" render "$scenes"/alpha-blend.glb --backend cuda \
      -o "$out/racecheck.png" --size 320x240
    step memcheck-ocmt "${cs[@]}" --tool memcheck "$k" render "$scenes"/near-clip.glb \
      --backend cuda-ocmt -o "$out/memcheck-ocmt.png" --size 320x240
  else
    echo "SKIP sanitizer: compute-sanitizer not on PATH" | tee -a "$summary"
  fi

  step bench "$k" bench "${all[@]}" --backends cpu,cuda,cuda-ocot,cuda-ocmt,gl --frames 10 --warmup 3
  cat "$out/bench.log" >>"$summary"

  scaling() {
    local t threads=(1 2 4 8 16)
    for t in "${threads[@]}"; do
      "$k" bench "${all[@]}" --threads "$t" --frames 20 --json >"$out/scaling-$t.json" || return 1
    done
    python3 - "$out" "${threads[@]}" <<'PY'
import json, math, sys
out, threads = sys.argv[1], sys.argv[2:]
ms = {t: {j["scene"]: j["median_ms"] for j in map(json.loads, open(f"{out}/scaling-{t}.json"))}
      for t in threads}
first, last = threads[0], threads[-1]
ratios = []
print(f"{'scene':28} " + " ".join(f"{t:>8}" for t in ms) + f"    {last}/{first}")
for s in ms[first]:
    r = ms[first][s] / ms[last][s]
    ratios.append(r)
    print(f"{s:28} " + " ".join(f"{ms[t][s]:8.3f}" for t in ms) + f" {r:7.2f}")
print(f"{'geometric mean':28} " + " " * (9 * len(ms)) + f" {math.exp(sum(map(math.log, ratios)) / len(ratios)):7.2f}")
PY
  }
  step scaling scaling
  cat "$out/scaling.log" >>"$summary"
  echo "logs in $out"
  return $failed
}

cmd="${1:-}"
[ $# -gt 0 ] && shift
case "$cmd" in
  build) build "$@" ;;
  run) run "$@" ;;
  *) echo "usage: $0 build [DIR] | run [KANTELE [OUT]]" >&2; exit 2 ;;
esac
