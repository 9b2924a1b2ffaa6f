#!/usr/bin/env python3
"""morphkit import --target-normals none: every target loses its normal deltas (and only them:
the base normals, the targets, their positions and tangent deltas stay), the blob is smaller,
positions play the same bytes, and surface normals still work on it; auto (the default) writes
the same blob as no option.

usage: test_target_normals.py MORPHKIT MAKE_EXAMPLE   (the FBX and glTF checks skip without the corpus)"""
import json, os, subprocess, sys

mk, make_example = sys.argv[1], sys.argv[2]
from cli_check import check, corpus, finish, have_corpus, read_bytes, runner, scratch, skip

work = scratch("mk_target_normals_")

run = runner(mk, timeout=300)



def info(path):
    rc, out, err = run("info", path, "--json")
    return json.loads(out) if rc == 0 else None


def targets(doc):
    return [(m["name"], c["name"], t["name"], t["vertices"], t["precision"], t["normals"], t["tangents"])
            for m in doc["meshes"] for c in m["channels"] for t in c["targets"]]


def frame(path, *extra):
    out = os.path.join(work, "frame.json")
    rc, _, err = run("play", path, "-o", out, "--time", "0.5", *extra)
    if rc:
        return None, err
    with open(out) as f:
        return json.load(f), err


def check_source(name, source):
    plain, auto, none = (os.path.join(work, name + s + ".morph") for s in ("", "_auto", "_none"))
    rcs = [run("import", source, "-o", plain, "--quiet")[0], run("import", source, "-o", auto, "--quiet",
           "--target-normals", "auto")[0]]
    rc, out, err = run("import", source, "-o", none, "--quiet", "--target-normals", "none")
    check(name + ": imports with auto, none and without the option", rcs == [0, 0] and rc == 0, err)
    if rc or any(rcs):
        return
    check(name + ": auto is the default (the same blob)", read_bytes(plain) == read_bytes(auto))
    a, n = info(auto), info(none)
    ta, tn = targets(a), targets(n)
    check(name + ": the file has target normals to drop", any(t[5] for t in ta), str(ta))
    check(name + ": none stores no target normals", not any(t[5] for t in tn), str(tn))
    # A target stores the vertices it moves; computed target normals add those whose normal
    # changes (the moved vertices' neighbours), so without normals a target may store fewer.
    keys = lambda ts: [t[:3] + t[4:5] + t[6:] for t in ts]
    check(name + ": the same targets, precisions and tangent deltas otherwise", keys(ta) == keys(tn),
          str(ta) + "\n" + str(tn))
    check(name + ": no target stores more vertices", all(b[3] <= x[3] for x, b in zip(ta, tn)), str(ta) + "\n" + str(tn))
    check(name + ": base normals kept", [m["normals"] for m in a["meshes"]] == [m["normals"] for m in n["meshes"]])
    check(name + ": the blob is smaller", n["bytes"] < a["bytes"], "%d vs %d" % (n["bytes"], a["bytes"]))
    fa, ea = frame(auto)
    fn, en = frame(none)
    check(name + ": both play", fa is not None and fn is not None, ea + en)
    if fa is None or fn is None:
        return
    pos = lambda f: [m.get("positions") for m in f["meshes"]]
    check(name + ": positions play the same", pos(fa) == pos(fn))
    fs, es = frame(none, "--normals", "surface")
    check(name + ": surface normals play without target normals", fs is not None and all(m.get("normals") for m in fs["meshes"]),
          es)


example = os.path.join(work, "ex.morph")
subprocess.run([make_example, example], check=True, capture_output=True)
check_source("morph", example)
if have_corpus:
    check_source("fbx", os.path.join(corpus, "fbx", "blender440_shape_weight_anim_7400_binary.fbx"))
    check_source("gltf", os.path.join(corpus, "gltf", "AnimatedMorphCube", "glTF", "AnimatedMorphCube.gltf"))
else:
    skip("fbx and gltf --target-normals", "no corpus at " + corpus)

rc, out, err = run("import", "--help")
check("--target-normals is documented in the help", rc == 0 and "--target-normals" in out, out + err)
rc, out, err = run("import", example, "-o", os.path.join(work, "bad.morph"), "--target-normals", "some")
check("an unknown choice is a usage error naming the option", rc == 2 and "--target-normals" in err, err)
finish()
