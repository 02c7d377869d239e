#!/bin/bash
# The official 3D Tiles validator on tilesets `meshstream tiles` writes from the bunny fixture:
# meshopt, Draco and plain content, placed on the globe or not, each with 0 errors and 0
# warnings (validate.sh --strict). Also `info` on a tileset, and the refusal of a non-empty OUTDIR (exit 2, the
# directory kept).
#   validate_tilesets.sh MESHSTREAM FIXTURES_DIR VALIDATOR_SOURCE VALIDATOR_DIR
# Exit 77 (ctest's skip) with the reason when the validator's source (../shared) or node is
# absent; the validator is set up into VALIDATOR_DIR when it is not there yet.
set -u
meshstream=$1 fixtures=$2 source=$3 validator=$4
if [ ! -x "$source/validate.sh" ]; then
  echo "SKIPPED: the 3D Tiles validator's source is not at $source (../shared/peers beside the checkout)"
  exit 77
fi
if ! command -v node >/dev/null; then
  echo "SKIPPED: node is not installed (tools/bootstrap.sh installs it)"
  exit 77
fi
if [ ! -d "$validator" ] || ! bash "$source/setup.sh" "$validator" >/dev/null 2>&1; then
  bash "$source/setup.sh" "$validator" || { echo "FAILED: cannot set up the validator in $validator"; exit 1; }
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
status=0
# The last case: 300 triangles a tile, five depths, so external tilesets from depth 3.
for case in "meshopt" "draco" "none" "meshopt --origin 7.4474,46.9480,540" "meshopt --tile-triangles 300"; do
  name=${case// /_}
  name=${name//[,.-]/_}
  options="--compress $case"
  [[ $case == *--tile-triangles* ]] || options+=" --tile-triangles 5000"
  # shellcheck disable=SC2086  # the words are options
  if ! "$meshstream" -q tiles "$fixtures/bunny_from_draco.bin.stl" "$work/$name" $options; then
    echo "FAILED: meshstream tiles --compress $case"
    status=1
    continue
  fi
  if bash "$source/validate.sh" --strict "$work/$name/tileset.json" "$validator" > "$work/$name.report" 2>&1; then
    echo "ok: --compress $case: $(grep numErrors "$work/$name.report")"
  else
    echo "FAILED: --compress $case:"
    grep -E "numErrors|ERROR|WARNING" "$work/$name.report" | head -20
    status=1
  fi
done
if [ -z "$(find "$work/meshopt___tile_triangles_300/tiles" -name '*.json')" ]; then
  echo "FAILED: 300 triangles a tile wrote no external tileset"
  status=1
fi
# info reads a tileset: its version and levels (the bunny at 5 000 a tile: three levels).
info=$("$meshstream" info "$work/meshopt/tileset.json")
if ! grep -q "format:      3D Tiles 1.1 tileset" <<<"$info" || ! grep -q "depth:       3 levels" <<<"$info"; then
  echo "FAILED: meshstream info on a tileset said: $info"
  status=1
fi
# A pipe is spooled: the same leaves, the input named as it came.
if ! "$meshstream" -q tiles - "$work/pipe" --tile-triangles 5000 --json < "$fixtures/bunny_from_draco.bin.stl" > "$work/pipe.json" ||
  ! grep -q '"inputs":\[{"path":"-","format":"stl"' "$work/pipe.json" ||
  ! grep -q '"triangles_in":69451' "$work/pipe.json"; then
  echo "FAILED: tiles from a pipe: $(cat "$work/pipe.json")"
  status=1
fi
# A non-empty OUTDIR: exit 2, nothing touched.
mkdir -p "$work/full" && echo mine > "$work/full/keep.txt"
"$meshstream" -q tiles "$fixtures/bunny_from_draco.bin.stl" "$work/full" 2> "$work/full.err"
rc=$?
if [ $rc -ne 2 ] || ! grep -q "the directory is not empty" "$work/full.err" || [ "$(ls "$work/full")" != keep.txt ]; then
  echo "FAILED: a non-empty OUTDIR gave exit $rc: $(cat "$work/full.err")"
  status=1
fi
exit $status
