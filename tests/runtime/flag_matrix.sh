#!/bin/sh
# The runtime gives the same bytes under any compiler and flags: builds the runtime's sources
# and determinism_driver.c with gcc and clang, -std=c11 and gnu11, -O2, -O3 and -O3
# -march=native, with and without the AVX2 clone, runs each build over the same blobs and
# expects one hash from all of them and from this build's own library (DRIVER).
# usage: flag_matrix.sh SOURCE_ROOT DRIVER MAKE_EXAMPLE [MORPHKIT]
src="$1"; driver="$2"; make_example="$3"; morphkit="${4:-}"
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
passed=0; failed=0; skipped=0
"$make_example" "$dir/example.morph" >/dev/null || { echo "FAIL make_example"; echo "0 passed, 1 failed"; exit 1; }
corpus="${MORPHKIT_CORPUS:-$src/../shared/corpus}"
if [ -n "$morphkit" ] && [ -d "$corpus" ]; then
  for f in fbx/maya_blend_inbetween_7500_ascii.fbx fbx/blender_279_shape_weights_7400_binary.fbx \
           fbx/max7_blend_cube_5000_binary.fbx gltf/MorphStressTest/glTF/MorphStressTest.gltf \
           gltf/AnimatedMorphCube/glTF/AnimatedMorphCube.gltf; do
    name=$(basename "$f" | sed 's/\.[a-z]*$//')
    "$morphkit" import "$corpus/$f" -o "$dir/$name.morph" >/dev/null 2>&1
    "$morphkit" import "$corpus/$f" --stacking sequential --precision float -o "$dir/$name.seq.morph" >/dev/null 2>&1
  done
fi
blobs=$(ls "$dir"/*.morph)
expected=$("$driver" $blobs) || { echo "FAIL the build's own driver"; echo "0 passed, 1 failed"; exit 1; }
echo "this build: $expected over $(echo $blobs | wc -w) blobs"
for cc in gcc clang; do
  if ! command -v $cc >/dev/null 2>&1; then echo "skip $cc: not installed"; skipped=$((skipped+1)); continue; fi
  for std in c11 gnu11; do
    for opt in "-O2" "-O3" "-O3 -march=native"; do
      for clones in "" "-DMK_NO_TARGET_CLONES"; do
        flags="-std=$std $opt $clones"
        if ! $cc $flags -I"$src/runtime/include" -I"$src/runtime" "$src"/runtime/open.c "$src"/runtime/eval.c "$src"/runtime/plan.c \
             "$src"/runtime/curve.c "$src"/runtime/checksum.c "$src"/runtime/error.c "$src"/runtime/surface.c "$src/tests/runtime/determinism_driver.c" -lm \
             -o "$dir/d" 2>"$dir/log"; then
          failed=$((failed+1)); echo "FAIL $cc $flags: does not build"; head -5 "$dir/log"; continue
        fi
        got=$("$dir/d" $blobs)
        if [ "$got" = "$expected" ]; then passed=$((passed+1)); echo "ok   $cc $flags"
        else failed=$((failed+1)); echo "FAIL $cc $flags: $got, expected $expected"; fi
      done
    done
  done
done
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
