#!/usr/bin/env bash
# Builds the `kantele` command with profile-guided optimisation (PGO): an instrumented build
# renders the built-in scenes and 400 generated cubes (one draw each) at every instruction-set
# level this machine has, with one and two threads, 4× multisampling, the 8-bit target and
# every traversal strategy, plus a far teapot and a full-screen cube; LLVM then compiles
# the release build again, laid out and inlined by those counts. The pictures are the same bits
# as a plain `cargo build --release` (PGO changes code layout and inlining, not arithmetic).
# BENCHMARKS.md has what it gains.
#
# Usage: scripts/pgo-build.sh [FEATURES]     (default: gl; e.g. "full", or "" for the lean CLI)
# Needs llvm-profdata of the toolchain's LLVM: `rustup component add llvm-tools`.
# Output: target/pgo/kantele (the binary), target/pgo/kantele.profdata (the merged profile).
set -euo pipefail

features=${1-gl}
root=$(cd "$(dirname "$0")/.." && pwd)
out=${CARGO_TARGET_DIR:-$root/target}/pgo
profdata=$(rustc --print sysroot)/lib/rustlib/$(rustc -vV | sed -n 's/^host: //p')/bin/llvm-profdata
if [[ ! -x $profdata ]]; then
    echo "pgo-build: no llvm-profdata at $profdata; run: rustup component add llvm-tools" >&2
    exit 1
fi
feature_args=()
[[ -n $features ]] && feature_args=(--features "$features")
rm -rf "$out/raw"
mkdir -p "$out/raw"

echo "pgo-build: 1/3 instrumented build" >&2
RUSTFLAGS="${RUSTFLAGS:-} -Cprofile-generate=$out/raw" cargo build --release --locked \
    -p kantele-cli "${feature_args[@]}" --target-dir "$out/instrumented"
kantele=$out/instrumented/release/kantele

echo "pgo-build: 2/3 training on the built-in scenes and generated cubes" >&2
# 400 cubes, one OBJ object (one draw) each: the per-draw paths of scenes with many objects.
awk 'BEGIN { n = 0; split("1 3 4 2|5 6 8 7|1 2 6 5|3 7 8 4|1 5 7 3|2 4 8 6", side, "|")
    for (i = 0; i < 20; i++) for (j = 0; j < 20; j++) {
        printf "o cube_%d_%d\n", i, j
        for (k = 0; k < 8; k++) printf "v %g %g %g\n", 1.5 * i + k % 2, int(k / 2) % 2, 1.5 * j + int(k / 4)
        for (f = 1; f <= 6; f++) { split(side[f], q, " "); b = 8 * n
            printf "f %d %d %d\nf %d %d %d\n", b + q[1], b + q[2], b + q[3], b + q[1], b + q[3], b + q[4] }
        n++ } }' >"$out/training-cubes.obj"
scenes=(--builtin cube --builtin teapot --builtin ground --builtin pixel-edges
    "$out/training-cubes.obj")
# The instruction-set levels this CPU has, as the renderer itself decides (`Isa::supported`):
# it replaces a level the CPU lacks by its best one, and `bench --json` names the level used.
# One warm-up frame and no timed warm-up: training needs the paths' counts, not steady times.
quick=(--warmup 1 --warmup-ms 0)
levels=()
for isa in scalar sse2 sse41 avx2 avx512 neon; do
    # (A level the CPU lacks also prints a warning, expected here: not shown.)
    used=$(KANTELE_ISA=$isa "$kantele" bench --builtin pixel-edges --frames 1 --warmup 0 --warmup-ms 0 --json \
        2>/dev/null)
    if [[ $used == *"\"isa\":\"$isa\""* ]]; then
        levels+=("$isa")
    fi
done
for isa in "${levels[@]}"; do
    # The scalar level is the readable reference, slow when instrumented: fewer frames.
    frames=10
    [[ $isa == scalar ]] && frames=2
    for threads in 1 2; do
        KANTELE_ISA=$isa "$kantele" bench "${scenes[@]}" --frames "$frames" "${quick[@]}" \
            --threads "$threads" >/dev/null
    done
    KANTELE_ISA=$isa "$kantele" bench "${scenes[@]}" --frames 3 "${quick[@]}" --msaa 4 >/dev/null
    KANTELE_ISA=$isa "$kantele" bench "${scenes[@]}" --frames 3 "${quick[@]}" --target srgb8 \
        >/dev/null
done
# Small triangles (a far teapot) and full-screen fill (a close cube), beside the scenes' own sizes.
"$kantele" bench --builtin teapot --size 160x120 --frames 20 "${quick[@]}" >/dev/null
"$kantele" bench --builtin cube --size 2048x1536 --frames 3 "${quick[@]}" >/dev/null
for strategy in bbox incremental block adaptive; do
    "$kantele" bench "${scenes[@]}" --frames 3 "${quick[@]}" --strategy "$strategy" >/dev/null
done
"$kantele" render --builtin teapot -o "$out/training-teapot.png"
"$profdata" merge -o "$out/kantele.profdata" "$out/raw"

echo "pgo-build: 3/3 optimised build" >&2
RUSTFLAGS="${RUSTFLAGS:-} -Cprofile-use=$out/kantele.profdata" cargo build --release --locked \
    -p kantele-cli "${feature_args[@]}" --target-dir "$out/optimised"
cp "$out/optimised/release/kantele" "$out/kantele"
echo "pgo-build: $out/kantele" >&2
