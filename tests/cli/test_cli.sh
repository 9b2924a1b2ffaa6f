#!/bin/sh
# The CLI end to end on the generated example: info (text and JSON), play (JSON, OBJ,
# weights, stacking, normals, spaces), conform with forced weights, bench, import errors,
# usage errors, atomic outputs, FBX export and write-back.
# usage: test_cli.sh MORPHKIT MAKE_EXAMPLE
mk="$1"; make_example="$2"
src=$(cd "$(dirname "$0")/../.." && pwd)
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
passed=0; failed=0
ok() { passed=$((passed+1)); echo "ok   $1"; }
bad() { failed=$((failed+1)); echo "FAIL $1"; }
check() { name="$1"; shift; if "$@" >"$dir/out" 2>&1; then ok "$name"; else bad "$name"; cat "$dir/out"; fi; }
check_fails() { name="$1"; code="$2"; shift 2; "$@" >"$dir/out" 2>&1; rc=$?
  if [ "$rc" -eq "$code" ]; then ok "$name"; else bad "$name (exit $rc, expected $code)"; cat "$dir/out"; fi; }

check "make example" "$make_example" "$dir/ex.morph"
check "info text" sh -c "'$mk' info '$dir/ex.morph' | grep -q \"channel 1 'bend': default 0, 4 targets (progressive)\""
check "info json parses" sh -c "'$mk' info '$dir/ex.morph' --json | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d[\"meshes\"][0][\"channels\"][1][\"targets\"][3][\"full_weight\"] == 1'"
check "play json" "$mk" play "$dir/ex.morph" --clip wave --time 1 -o "$dir/f.json"
check "play json shape" python3 -c "
import json; d = json.load(open('$dir/f.json'))
m = d['meshes'][0]
assert m['name'] == 'tube' and len(m['positions']) == 3 * 800 and len(m['normals']) == 3 * 800
assert abs(m['channels'][0]['weight'] - 1) < 1e-6 and abs(m['channels'][1]['weight'] - 0.5) < 1e-6"
check "play obj" sh -c "'$mk' play '$dir/ex.morph' --time 0.5 -o '$dir/f.obj' && grep -c '^v ' '$dir/f.obj' | grep -qx 800 && grep -c '^f ' '$dir/f.obj' | grep -qx 1536"
check "play weights by name" "$mk" play "$dir/ex.morph" --weights bend=1,bulge=0.25 --stacking sequential --normals slerp --space local -o "$dir/w.json"
check "play --normals surface: unit normals from the surface, not the blended ones" sh -c "'$mk' play '$dir/ex.morph' --time 1 --normals surface -o '$dir/s.json' && '$mk' play '$dir/ex.morph' --time 1 -o '$dir/n.json' && python3 -c 'import json,math; s=json.load(open(\"$dir/s.json\")); n=json.load(open(\"$dir/n.json\")); a=s[\"meshes\"][0][\"normals\"]; b=n[\"meshes\"][0][\"normals\"]; assert s[\"normals\"] == \"surface\"; assert all(abs(math.sqrt(a[i]**2+a[i+1]**2+a[i+2]**2)-1) < 1e-4 for i in range(0,len(a),3)); assert max(abs(x-y) for x,y in zip(a,b)) > 1e-3; assert s[\"meshes\"][0][\"positions\"] == n[\"meshes\"][0][\"positions\"]'"
check "weights applied" python3 -c "
import json; d = json.load(open('$dir/w.json'))
w = {c['name']: c['weight'] for c in d['meshes'][0]['channels']}
assert w == {'bulge': 0.25, 'bend': 1.0}, w"
check "rest pose equals base" python3 -c "
import json, subprocess
subprocess.run(['$mk', 'play', '$dir/ex.morph', '--weights', 'bend=0,bulge=0', '--space', 'local', '-o', '$dir/r.json'], check=True)
p = json.load(open('$dir/r.json'))['meshes'][0]['positions']
assert abs(p[0] - 0.5) < 1e-6 and abs(p[1]) < 1e-6"
check_fails "unknown verb" 2 "$mk" frobnicate
check_fails "play without output" 2 "$mk" play "$dir/ex.morph"
check_fails "unknown channel" 2 "$mk" play "$dir/ex.morph" --weights nope=1 -o "$dir/x.json"
check_fails "unknown clip" 2 "$mk" play "$dir/ex.morph" --clip nope -o "$dir/x.json"
check "no output file after a failure" test ! -e "$dir/x.json"
printf 'not a morph file at all' > "$dir/junk.morph"
check_fails "info on junk" 1 "$mk" info "$dir/junk.morph"
head -c 200 "$dir/ex.morph" > "$dir/trunc.morph"
check_fails "info on truncated blob" 1 "$mk" info "$dir/trunc.morph"
cp "$dir/out" "$dir/trunc.out"
check "truncation message names it" grep -q "shorter than the header's file size" "$dir/trunc.out"
check_fails "import of a missing file" 1 "$mk" import "$dir/missing.fbx" -o "$dir/y.morph"
check "no output after failed import" test ! -e "$dir/y.morph"
check "import of a .morph rewrites it" "$mk" import "$dir/ex.morph" -o "$dir/re.morph" --precision float
check "the rewritten file is the same asset in float" sh -c "'$mk' info '$dir/re.morph' --json | python3 -c 'import json,sys; d=json.load(sys.stdin); m=d[\"meshes\"][0]; assert d[\"float_targets\"] == 5 and d[\"quantized_targets\"] == 0 and [c[\"name\"] for c in m[\"channels\"]] == [\"bulge\", \"bend\"], d'"
check "no temporary files left" sh -c "! ls '$dir' | grep -q '\.tmp\.'"
# FBX: export writes the asset as FBX that plays as the blob; bake writes back into an FBX input.
check "export to fbx" "$mk" export "$dir/ex.morph" -o "$dir/ex.fbx"
check "the fbx plays as the blob (per control point)" sh -c "'$mk' play '$dir/ex.morph' --clip wave --time 1 -o '$dir/pm.json' && '$mk' play '$dir/ex.fbx' --clip wave --time 1 -o '$dir/pf.json' && python3 -c 'import json; m=[json.load(open(f))[\"meshes\"][0] for f in (\"$dir/pm.json\", \"$dir/pf.json\")]; p=[{c: x[\"positions\"][3*v:3*v+3] for v, c in enumerate(x[\"control_points\"])} for x in m]; assert p[0].keys() == p[1].keys() and max(abs(a-b) for c in p[0] for a,b in zip(p[0][c], p[1][c])) < 1e-5'"
check "bake into the fbx" "$mk" bake "$dir/ex.fbx" --recipe "$src/samples/recipes/barr.json" -o "$dir/baked.fbx" --quiet
check "the baked fbx has the new channels after its own" sh -c "'$mk' info '$dir/baked.fbx' --json | python3 -c 'import json,sys; d=json.load(sys.stdin); n=[c[\"name\"] for c in d[\"meshes\"][0][\"channels\"]]; assert n == [\"bulge\", \"bend\", \"taper_top\", \"bend_forward\", \"twist_quarter\"], n'"
mkfifo "$dir/pipe.fbx" && (cat "$dir/ex.fbx" > "$dir/pipe.fbx" &)
check "bake into an fbx read from a pipe (read once)" timeout 120 "$mk" bake "$dir/pipe.fbx" --recipe "$src/samples/recipes/barr.json" -o "$dir/piped.fbx" --quiet
check "the piped bake is the same file" cmp "$dir/baked.fbx" "$dir/piped.fbx"
printf '{ "channels": [] }' > "$dir/empty.json"
check "an empty recipe writes the fbx back byte for byte" sh -c "'$mk' bake '$dir/ex.fbx' --recipe '$dir/empty.json' -o '$dir/same.fbx' --quiet && cmp '$dir/ex.fbx' '$dir/same.fbx'"
check_fails "bake of a blob into an fbx" 1 "$mk" bake "$dir/ex.morph" --recipe "$src/samples/recipes/barr.json" -o "$dir/nope.fbx"
cp "$dir/out" "$dir/refusal.out"
check "that refusal names the input" grep -q "an .fbx output is the FBX input" "$dir/refusal.out"
check "and writes nothing" test ! -e "$dir/nope.fbx"
check_fails "export to fbx takes no sidecar" 2 "$mk" export "$dir/ex.morph" -o "$dir/nope.fbx" --no-sidecar
# conform: an OBJ reference frame with forced weights (the frame's "weights", in the mesh's
# channel order) is compared with those weights, not the clip's; wrong weights fail.
"$mk" play "$dir/ex.morph" --weights bulge=0.25,bend=1 --space local -o "$dir/forced.obj" >/dev/null
forced_case() { # manifest path, forced weights
  printf '{ "version": 1, "cases": [ { "name": "forced", "source": "ex.morph", "format": "fbx",
  "reference": { "kind": "obj", "space": "mesh-local", "match": "vertices", "tolerance": 1e-5 },
  "frames": [ { "weights": [%s], "file": "forced.obj" } ] } ] }\n' "$2" > "$1"; }
forced_case "$dir/forced_right.json" "0.25, 1"
forced_case "$dir/forced_wrong.json" "0, 0"
check "conform obj frame with forced weights" "$mk" conform "$dir/forced_right.json" --precision float
check_fails "conform obj frame with other forced weights fails" 1 "$mk" conform "$dir/forced_wrong.json" --precision float
check "bench runs (small)" sh -c "'$mk' bench --vertices 5000 --channels 10 --active 3 --frames 5 --json | python3 -c 'import json,sys; d=json.load(sys.stdin); assert set(d) == {\"ns_per_frame\",\"ns_per_frame_positions\",\"bytes_per_frame\",\"bound_ns\",\"ratio_to_bound\",\"naive_ns\",\"speedup_vs_naive\",\"sequential_over_additive\"}'"
check "bench on a file measures it" sh -c "'$mk' bench '$dir/ex.morph' --frames 10 --json | python3 -c 'import json,sys; d=json.load(sys.stdin); assert d[\"ns_per_frame\"] > 0 and d[\"bytes_per_frame\"] > 0 and d[\"speedup_vs_naive\"] > 0, d; assert d[\"normals_measured\"] > 0 and 0 <= d[\"normals_nlerp_mean_deg\"] <= d[\"normals_nlerp_p99_deg\"] <= d[\"normals_nlerp_max_deg\"] < d[\"normals_base_max_deg\"] and d[\"normals_slerp_max_deg\"] >= 0 and d[\"normals_surface_max_deg\"] < 0.01 < d[\"normals_nlerp_max_deg\"] and d[\"ns_per_frame_surface\"] > 0 and d[\"ns_per_frame_surface_without_target_normals\"] > 0 and d[\"surface_without_target_normals_over_nlerp\"] > 0, d'"
check "bench --threads 2 reports in-process scaling" sh -c "'$mk' bench --vertices 20000 --channels 10 --active 3 --frames 5 --threads 2 | python3 -c 'import re,sys; t=sys.stdin.read(); m=re.search(r\"^thread_scaling +([0-9.]+)  \\(1 thread ([0-9]+) ns, 2 threads ([0-9]+) ns\", t, re.M); s=re.search(r\"^least_thread_share +([0-9.]+) \", t, re.M); assert m and float(m.group(1)) > 0 and int(m.group(2)) > 0 and int(m.group(3)) > 0; assert s and 0 <= float(s.group(1)) <= 0.5'"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
