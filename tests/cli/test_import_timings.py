#!/usr/bin/env python3
"""morphkit import --timings: the phase table on standard error (one line per phase, its seconds,
share and peak memory, then the total), the phases each input kind goes through, and the blob
it writes byte for byte the same as without the option.

usage: test_import_timings.py MORPHKIT MAKE_EXAMPLE   (the FBX and glTF checks skip without the corpus)"""
import os, re, subprocess, sys

mk, make_example = sys.argv[1], sys.argv[2]
from cli_check import check, corpus, finish, have_corpus, read_bytes, runner, scratch, skip

work = scratch("mk_import_timings_")
LINE = re.compile(r"^(\S.*?)\s+(\d+\.\d{3})\s+(\d+\.\d)%\s+(\d+\.\d) MB$")
TOTAL = re.compile(r"^total\s+(\d+\.\d{3})\s+(\d+\.\d) MB$")

run = runner(mk, timeout=300)



def table(err):
    """The phase table at the end of standard error: [(name, seconds, share, MB)], (total, MB)."""
    lines = err.splitlines()
    start = next((i for i, l in enumerate(lines) if re.match(r"^phase\s+seconds\s+share\s+peak memory$", l)), None)
    if start is None:
        return None, None
    phases, total = [], None
    for l in lines[start + 1:]:
        t = TOTAL.match(l)
        if t:
            total = (float(t.group(1)), float(t.group(2)))
            break
        m = LINE.match(l)
        if not m:
            return None, None
        phases.append((m.group(1), float(m.group(2)), float(m.group(3)), float(m.group(4))))
    return phases, total


def check_import(name, source, expected):
    plain, timed = os.path.join(work, name + ".morph"), os.path.join(work, name + "_t.morph")
    rc0, _, err0 = run("import", source, "-o", plain, "--quiet")
    rc, out, err = run("import", source, "-o", timed, "--quiet", "--timings")
    check(name + ": imports with and without --timings", rc0 == 0 and rc == 0, err0 + err)
    if rc0 or rc:
        return
    check(name + ": no phase table without --timings", "peak memory" not in err0, err0)
    check(name + ": the results still go to standard output", "->" in out and "peak memory" not in out, out)
    phases, total = table(err)
    check(name + ": a phase table ending in a total", phases is not None and total is not None, err)
    if not phases or not total:
        return
    names = [p[0] for p in phases]
    check(name + ": phases in order " + ", ".join(expected),
          [n for n in names if n in expected] == expected, "got: " + ", ".join(names))
    check(name + ": every phase once", len(set(names)) == len(names), ", ".join(names))
    seconds = sum(p[1] for p in phases)
    check(name + ": the total is the sum of the phases", abs(seconds - total[0]) <= 0.0005 * len(phases) + 1e-9,
          "%g vs %g" % (seconds, total[0]))
    shares = sum(p[2] for p in phases)
    check(name + ": shares add up to 100 %", total[0] == 0 or abs(shares - 100) <= 0.05 * len(phases) + 0.1,
          "%g" % shares)
    # A phase that runs more than once (FBX "scene") shows the peak at its last end, so the
    # column need not rise line by line; the total's is the largest.
    check(name + ": peak memory known for every phase, the largest is the total's",
          all(p[3] > 0 for p in phases) and total[1] == max(p[3] for p in phases), err)
    check(name + ": the blob is the same with --timings", read_bytes(plain) == read_bytes(timed))


common = ["validate", "quantize", "lay out blocks", "assemble and checksum", "write file", "release"]
example = os.path.join(work, "ex.morph")
subprocess.run([make_example, example], check=True, capture_output=True)
check_import("morph", example, ["read file", "open and read blob"] + common)

if have_corpus:
    fbx = os.path.join(corpus, "fbx", "blender440_shape_weight_anim_7400_binary.fbx")
    check_import("fbx", fbx, ["read file", "parse", "meshes", "shapes", "animation", "release parse data",
                              "target normals"] + common)
    gltf = os.path.join(corpus, "gltf", "SimpleMorph", "glTF", "SimpleMorph.gltf")
    check_import("gltf", gltf, ["read file", "parse", "convert", "release parse data"] + common)
else:
    skip("fbx and gltf --timings", "no corpus at " + corpus)

rc, out, err = run("import", "--help")
check("--timings is documented in the help", rc == 0 and "--timings" in out, out + err)
finish()
