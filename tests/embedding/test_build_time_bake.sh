#!/bin/sh
# samples/build_time_bake as a game's build would use it: morphkit as a subproject whose command
# imports, bakes and embeds the asset with depfiles. Checks that the program plays the baked
# channels, that a second ninja does nothing, and that touching the recipe, a cage it names or
# the source asset reruns exactly the steps downstream of it.
# usage: test_build_time_bake.sh SOURCE_ROOT
src="$1"
dir=$(mktemp -d); trap 'rm -rf "$dir"' EXIT
passed=0; failed=0
ok() { passed=$((passed+1)); echo "ok   $1"; }
bad() { failed=$((failed+1)); echo "FAIL $1"; [ -f "$dir/log" ] && tail -30 "$dir/log"; }
cp -r "$src/samples/build_time_bake" "$dir/game"
mkdir -p "$dir/game/subprojects"
ln -s "$src" "$dir/game/subprojects/morphkit"
b="$dir/game/build"
if ! meson setup "$b" "$dir/game" >"$dir/log" 2>&1 || ! ninja -C "$b" >>"$dir/log" 2>&1; then
  bad "the sample builds"; echo "$passed passed, $failed failed"; exit 1
fi
ok "the sample builds (import, bake, embed, compile)"
"$b/game" >"$dir/out" 2>&1 && grep -q "channel 0: lift" "$dir/out" && grep -q "channel 1: squash" "$dir/out" \
  && ok "the program plays the imported and the baked channel" || { cp "$dir/out" "$dir/log"; bad "the program's output"; }
# Top corner (0.5, 0.5, 0.5): lift raises it by 0.5, the squashed cage lowers it.
grep -q "weights 0.0: top corner at (0.500, 0.500, 0.500)" "$dir/out" && ok "weights 0 give the source box" \
  || { cp "$dir/out" "$dir/log"; bad "weights 0"; }

ninja -C "$b" >"$dir/log" 2>&1
grep -q "no work to do" "$dir/log" && ok "a second ninja does nothing" || bad "a second ninja rebuilt something"

steps() { # what the last ninja -v ran: the morphkit verbs and the link
  for verb in import bake embed; do grep -q "morphkit $verb\|morphkit' $verb\|morphkit\" $verb\|tools/morphkit $verb" "$dir/log" && printf '%s ' "$verb"; done
  grep -q -- "-o game\b\|-o game " "$dir/log" && printf 'link'
}
expect_steps() { # what was touched, the steps expected
  sleep 1; touch "$dir/game/$1"
  ninja -C "$b" -v >"$dir/log" 2>&1 || { bad "rebuild after touching $1"; return; }
  got=$(steps)
  if [ "$got" = "$2" ]; then ok "touching $1 reruns: $got"; else bad "touching $1 reran '$got', expected '$2'"; fi
}
expect_steps assets/recipe.json "bake embed link"
expect_steps assets/cage_squashed.obj "bake embed link"
expect_steps assets/box.gltf "import bake embed link"
ninja -C "$b" >"$dir/log" 2>&1
grep -q "no work to do" "$dir/log" && ok "and then nothing again" || bad "a ninja after the rebuilds rebuilt something"
echo "$passed passed, $failed failed"
[ "$failed" -eq 0 ]
