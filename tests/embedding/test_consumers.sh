#!/bin/sh
# Engines adopt the runtime three ways; each is built here as an engine would, outside the tree,
# and must play the same blobs to the same bytes as this build's library (determinism_driver
# prints a hash of everything it evaluates) and run the embedding sample:
#   1. pkg-config against an installed runtime-only build (static and shared);
#   2. a meson project with morphkit as a subproject: dependency('morphkit-runtime');
#   3. a CMake project with add_subdirectory(morphkit): morphkit::runtime.
# usage: test_consumers.sh SOURCE_ROOT DRIVER MAKE_EXAMPLE [MORPHKIT]
src="$1"; driver="$2"; make_example="$3"; morphkit="${4:-}"
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
passed=0; failed=0; skipped=0
ok() { passed=$((passed+1)); echo "ok   $1"; }
bad() { failed=$((failed+1)); echo "FAIL $1"; [ -f "$dir/log" ] && tail -20 "$dir/log"; }
"$make_example" "$dir/example.morph" >/dev/null || { echo "FAIL make_example"; echo "0 passed, 1 failed"; exit 1; }
corpus="${MORPHKIT_CORPUS:-$src/../shared/corpus}"
if [ -n "$morphkit" ] && [ -f "$corpus/gltf/MorphStressTest/glTF/MorphStressTest.gltf" ]; then
  "$morphkit" import "$corpus/gltf/MorphStressTest/glTF/MorphStressTest.gltf" -o "$dir/stress.morph" >/dev/null
  "$morphkit" import "$corpus/fbx/maya_blend_inbetween_7500_ascii.fbx" -o "$dir/inbetween.morph" >/dev/null
fi
blobs=$(ls "$dir"/*.morph)
expected=$("$driver" $blobs)
echo "this build: $expected over $(echo $blobs | wc -w) blobs"
check_program() { # name, program
  got=$("$2" $blobs 2>"$dir/log")
  if [ "$got" = "$expected" ]; then ok "$1 plays the blobs to the same bytes"; else bad "$1: $got, expected $expected"; fi
}

# 1. pkg-config against an installed runtime.
if command -v pkg-config >/dev/null 2>&1; then
  if meson setup "$dir/rt" "$src" -Druntime_only=true --prefix="$dir/prefix" --libdir=lib >"$dir/log" 2>&1 \
     && ninja -C "$dir/rt" install >>"$dir/log" 2>&1; then
    ok "runtime-only build installs"
    export PKG_CONFIG_PATH="$dir/prefix/lib/pkgconfig"
    for f in lib/libmorphkit_runtime.a lib/pkgconfig/morphkit-runtime.pc include/morphkit.h; do
      [ -f "$dir/prefix/$f" ] && ok "installed $f" || bad "not installed: $f"
    done
    ls "$dir/prefix/lib/"libmorphkit_runtime.so* >/dev/null 2>&1 && ok "installed the shared library" || bad "no shared library"
    if cc -std=c11 -O2 "$src/tests/runtime/determinism_driver.c" $(pkg-config --cflags --libs morphkit-runtime) \
         -Wl,-rpath,"$dir/prefix/lib" -o "$dir/pc_shared" 2>"$dir/log"; then check_program "pkg-config (shared)" "$dir/pc_shared"
    else bad "pkg-config (shared) build"; fi
    if cc -std=c11 -O2 "$src/tests/runtime/determinism_driver.c" $(pkg-config --static --cflags morphkit-runtime) \
         "$dir/prefix/lib/libmorphkit_runtime.a" $(pkg-config --static --libs-only-l morphkit-runtime | sed 's/-lmorphkit_runtime//') \
         -o "$dir/pc_static" 2>"$dir/log"; then check_program "pkg-config (static)" "$dir/pc_static"
    else bad "pkg-config (static) build"; fi
    if cc -std=c11 "$src/samples/embed_minimal.c" $(pkg-config --cflags --libs morphkit-runtime) -Wl,-rpath,"$dir/prefix/lib" \
         -o "$dir/embed" 2>"$dir/log" && "$dir/embed" "$dir/example.morph" >"$dir/out" 2>&1 && grep -q "last vertex" "$dir/out"; then
      ok "embed_minimal builds with pkg-config and plays the example"
    else bad "embed_minimal through pkg-config"; fi
  else bad "runtime-only build and install"; fi
else
  skipped=$((skipped+1)); echo "skip pkg-config route: pkg-config not installed"
fi

# 2. A meson project with morphkit as a subproject.
mkdir -p "$dir/game/subprojects"
ln -s "$src" "$dir/game/subprojects/morphkit"
cp "$src/tests/runtime/determinism_driver.c" "$dir/game/"
cat > "$dir/game/meson.build" <<'MESON'
project('game', 'c', default_options: ['c_std=gnu11', 'buildtype=release'])
runtime = dependency('morphkit-runtime', fallback: 'morphkit')
executable('play', 'determinism_driver.c', dependencies: runtime)
MESON
if meson setup "$dir/game/build" "$dir/game" --wrap-mode=forcefallback >"$dir/log" 2>&1 && ninja -C "$dir/game/build" >>"$dir/log" 2>&1; then
  ok "meson subproject builds (runtime only: no C++, no third-party dependency)"
  if grep -qiE "cjson|draco|tinygltf|cholmod|deflate" "$dir/game/build/meson-logs/meson-log.txt"; then
    bad "the subproject configured offline dependencies"
  else ok "the subproject configured no offline dependency"; fi
  if ls "$dir/game/build/subprojects/morphkit/offline" >/dev/null 2>&1; then bad "the subproject built the offline core"
  else ok "the subproject built the runtime only"; fi
  check_program "meson subproject" "$dir/game/build/play"
else bad "meson subproject build"; fi

# 3. A CMake project with add_subdirectory(morphkit).
if command -v cmake >/dev/null 2>&1; then
  mkdir -p "$dir/cgame"
  cp "$src/tests/runtime/determinism_driver.c" "$dir/cgame/"
  cat > "$dir/cgame/CMakeLists.txt" <<CMAKE
cmake_minimum_required(VERSION 3.13)
project(cgame C)
add_subdirectory("$src" morphkit)
add_executable(play determinism_driver.c)
target_link_libraries(play PRIVATE morphkit::runtime)
CMAKE
  if cmake -S "$dir/cgame" -B "$dir/cgame/build" -DCMAKE_BUILD_TYPE=Release >"$dir/log" 2>&1 \
     && cmake --build "$dir/cgame/build" >>"$dir/log" 2>&1; then
    ok "CMake add_subdirectory builds"
    check_program "CMake" "$dir/cgame/build/play"
  else bad "CMake build"; fi
else
  skipped=$((skipped+1)); echo "skip CMake route: cmake not installed"
fi
echo "$passed passed, $failed failed, $skipped skipped"
[ "$failed" -eq 0 ]
