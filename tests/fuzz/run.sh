#!/usr/bin/env bash
# Builds the libFuzzer targets and runs each for a set time, printing libFuzzer's final stats
# (executions, execs/s, coverage). Seed corpora come from fixtures/ (gzip fixtures decoded for
# the readers, kept compressed for the gzip target; the decimator gets generated grids).
# Corpora, crash artifacts and logs go under the build directory, never into the repository.
#
#   tests/fuzz/run.sh [seconds per target (600)] [targets... (all)]
#   BUILD_DIR=/path/to/build-fuzz JOBS=2 tests/fuzz/run.sh 600 ply obj
#   FUZZ_FLAGS="-fork=1 -ignore_crashes=1" tests/fuzz/run.sh 600 decimate   # keep going past findings
#
# Needs clang++ and libclang-rt-14-dev (libFuzzer's runtime). Exit status: non-zero when any
# target found a crash, leak, timeout or out-of-memory; its reproducer is printed.
set -euo pipefail
cd "$(dirname "$0")/../.."
SRC=$PWD
BUILD_DIR=${BUILD_DIR:-$SRC/build-fuzz}
JOBS=${JOBS:-2}
SECONDS_PER_TARGET=${1:-600}
shift || true
ALL=(stl_binary stl_ascii ply obj stream gzip draco gltf gltf_meshopt decimate)
[ $# -gt 0 ] && TARGETS=("$@") || TARGETS=("${ALL[@]}")

cmake -S "$SRC" -B "$BUILD_DIR" -DCMAKE_CXX_COMPILER=clang++ -DCMAKE_BUILD_TYPE=RelWithDebInfo \
      -DMESHSTREAM_BUILD_FUZZERS=ON -DMESHSTREAM_BUILD_TESTS=OFF >/dev/null
cmake --build "$BUILD_DIR" -j"$JOBS" --target "${TARGETS[@]/#/fuzz_}"

# Seeds: fixtures under 64 KiB (-max_len), by extension.
seed() {  # seed <target> <find -name patterns...>
    local dir=$BUILD_DIR/fuzz-corpus/$1; shift
    mkdir -p "$dir"
    local f
    while IFS= read -r -d '' f; do
        # Big fixtures are cut at 64 KiB (head closing the pipe early is expected).
        if [[ $f == *.gz && $dir != */gzip ]]; then
            { gzip -dc "$f" | head -c 65536 >"$dir/$(basename "${f%.gz}")"; } || true
        else
            head -c 65536 "$f" >"$dir/$(basename "$f")"
        fi
    done < <(find "$SRC/fixtures" -type f \( "$@" \) -print0)
}
seed stl_binary -name '*.stl' -o -name '*.stl.gz'
seed stl_ascii -name '*.stl' -o -name '*.stl.gz'
seed ply -name '*.ply' -o -name '*.ply.gz'
seed obj -name '*.obj' -o -name '*.obj.gz'
seed gzip -name '*.gz'
seed draco -name '*.drc'
seed gltf -name '*.glb' -o -name '*.gltf'
# EXT_meshopt_compression seeds (format in fuzz_gltf_meshopt.cpp): the compressed streams of
# the meshopt fixtures behind a few choices of stride, filter and index mode.
mkdir -p "$BUILD_DIR/fuzz-corpus/gltf_meshopt"
python3 - "$BUILD_DIR/fuzz-corpus/gltf_meshopt" "$SRC/fixtures/gltf" <<'PY'
import struct, sys
for name in ("elephant_meshopt.glb", "BoxTextured_gltfpack_cc.glb"):
    b = open(f"{sys.argv[2]}/{name}", "rb").read()
    n = struct.unpack("<I", b[12:16])[0]
    blob = b[28 + n:][:65000]
    for select in (1, 5, 6, 15, 17, 33):
        open(f"{sys.argv[1]}/{name}.{select}", "wb").write(bytes([select, 23, 12]) + blob)
PY
# Triangle stream seeds (layout in docs/formats.md): positions only, and every channel with a
# textured material, two chunks each.
mkdir -p "$BUILD_DIR/fuzz-corpus/stream"
python3 - "$BUILD_DIR/fuzz-corpus/stream" <<'PY'
import struct, sys
def s(b): return struct.pack("<I", len(b)) + b
def stream(name, body, record_bytes, chunks):
    out = b"\x89MSH\r\n\x1a\n" + struct.pack("<IQ", 1, len(body)) + body
    total = 0
    for n in chunks:
        out += struct.pack("<I", n) + bytes(range(256)) * (n * record_bytes // 256) + bytes(n * record_bytes % 256)
        total += n
    open(f"{sys.argv[1]}/{name}", "wb").write(out + struct.pack("<IQ", 0, total) + b"MSHE")
stream("positions", struct.pack("<QBBBBBBH", 2**64 - 1, 255, 0, 0, 0, 0, 0, 0) + struct.pack("<III", 0, 0, 0), 36, (3, 2))
body = struct.pack("<QBBBBBBH", 5, 2, 7, 3, 1, 2, 1, 0)
body += struct.pack("<I", 1) + bytes([6]) + s(b"intensity") + struct.pack("<I", 1) + bytes([4]) + s(b"label")
body += struct.pack("<I", 1) + s(b"wood") + struct.pack("<4f", 1, 1, 1, 1) + bytes([1]) + s(b"w.png") + s(b"image/png")
body += struct.pack("<Q", 4) + b"\x89PNG"
stream("channels", body, 36 + 36 + 48 + 48 + 24 + 24 + 4 + 8, (4, 1))
PY
# Decimator seeds (format in fuzz_decimate.cpp): n×n grids of unit squares, a few options.
mkdir -p "$BUILD_DIR/fuzz-corpus/decimate"
python3 - "$BUILD_DIR/fuzz-corpus/decimate" <<'PY'
import struct, sys
for n, opts in ((4, bytes([0, 64, 7, 0, 0, 8])), (7, bytes([1, 127, 3, 2, 1, 1])), (8, bytes([10, 30, 8, 3, 2, 20]))):
    pal = [(float(x), float(y), float((x * y) % 3)) for y in range(n) for x in range(n)]
    tris = []
    for y in range(n - 1):
        for x in range(n - 1):
            a, b, c, d = y * n + x, y * n + x + 1, (y + 1) * n + x, (y + 1) * n + x + 1
            tris += [a, b, d, a, d, c]
    data = opts + bytes([len(pal) - 1]) + b"".join(struct.pack("<3f", *p) for p in pal) + bytes(tris)
    open(f"{sys.argv[1]}/grid{n}", "wb").write(data)
PY

run_one() {
    local t=$1 dir=$BUILD_DIR/fuzz-out/$1
    mkdir -p "$dir"
    (cd "$dir" && "$BUILD_DIR/tests/fuzz/fuzz_$t" "$BUILD_DIR/fuzz-corpus/$t" \
        -max_total_time="$SECONDS_PER_TARGET" -max_len=65536 -timeout=20 -rss_limit_mb=2048 \
        -malloc_limit_mb=1024 -print_final_stats=1 -artifact_prefix="$dir/" ${FUZZ_FLAGS:-} >"$dir/log.txt" 2>&1) && rc=0 || rc=$?
    {
        echo "== $t (exit $rc)"
        grep -E '^(stat::|INFO: Loaded|#[0-9]+ *DONE)' "$dir/log.txt" | tail -n 12 || true
        grep -m1 -E 'cov:' "$dir/log.txt" | sed 's/^/first: /' || true
        grep -E 'cov:' "$dir/log.txt" | tail -n 1 | sed 's/^/last:  /' || true
        if [ $rc -ne 0 ]; then grep -E 'ERROR|SUMMARY|Test unit written' "$dir/log.txt" | head -n 5; fi
    } >"$dir/summary.txt"
    cat "$dir/summary.txt"
    return $rc
}

status=0
running=0
for t in "${TARGETS[@]}"; do
    run_one "$t" &
    running=$((running + 1))
    if [ $running -ge "$JOBS" ]; then wait -n || status=1; running=$((running - 1)); fi
done
while [ $running -gt 0 ]; do wait -n || status=1; running=$((running - 1)); done
exit $status
