#!/usr/bin/env python3
"""The command line must not hurt its users: every verb with -o pointing at a FIFO, a symbolic
link (also a dangling one), a device twin (mknod, when root), a directory and the input itself;
multi-file outputs all or nothing; output names that do not match the content; options that
used to be silently ignored; channel names shared by several glTF primitives or nodes; range
checks; the static state of conformance frames; messages and exit codes.

usage: test_cli_safety.py MORPHKIT MAKE_EXAMPLE   (corpus checks skip without the corpus)"""
import base64, hashlib, json, os, stat, struct, subprocess, sys, tempfile, threading

mk, make_example = sys.argv[1], sys.argv[2]
from cli_check import check, corpus, finish, have_corpus, root, runner, scratch, skip

work = scratch("mk_cli_safety_")

run = runner(mk, timeout=120)


def path(*parts):
    return os.path.join(work, *parts)


def digest(p):
    with open(p, "rb") as f:
        return hashlib.sha256(f.read()).hexdigest()


def expect(name, args, code, out_has=None, err_has=None):
    rc, out, err = run(*args)
    ok = rc == code and (out_has is None or out_has in out) and (err_has is None or err_has in err)
    check(name, ok, "exit %d (expected %d)\nstdout: %s\nstderr: %s" % (rc, code, out[-800:], err[-800:]))
    return rc, out, err


def write(p, text):
    with open(p, "w") as f:
        f.write(text)


# ---- fixtures ----
example = path("ex.morph")
subprocess.run([make_example, example], check=True, capture_output=True)

ICO = None


def plain_gltf(p, node_names=("ico",), with_targets=False, target_names=("smile",), delta=None):
    """A small glTF (a tetrahedron per node), plain or with one morph target per mesh (its 4
    position deltas `delta`, 12 floats; default: each vertex 0.5 up)."""
    pos = [0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]
    idx = [0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3]
    delta = delta or [0, 0, 0.5, 0, 0, 0.5, 0, 0, 0.5, 0, 0, 0.5]
    data = struct.pack("<12f", *pos) + struct.pack("<12H", *idx) + struct.pack("<12f", *delta)
    doc = {
        "asset": {"version": "2.0"},
        "buffers": [{"byteLength": len(data), "uri": "data:application/octet-stream;base64," + base64.b64encode(data).decode()}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 24},
                        {"buffer": 0, "byteOffset": 72, "byteLength": 48}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [0, 0, 0], "max": [1, 1, 1]},
                      {"bufferView": 1, "componentType": 5123, "count": 12, "type": "SCALAR"},
                      {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC3",
                       "min": [min(delta[c::3]) for c in range(3)], "max": [max(delta[c::3]) for c in range(3)]}],
        "meshes": [], "nodes": [], "scenes": [{"nodes": []}], "scene": 0,
    }
    for i, name in enumerate(node_names):
        prim = {"attributes": {"POSITION": 0}, "indices": 1}
        mesh = {"primitives": [prim]}
        if with_targets:
            prim["targets"] = [{"POSITION": 2}]
            mesh["extras"] = {"targetNames": [target_names[i % len(target_names)]]}
        doc["meshes"].append(mesh)
        doc["nodes"].append({"name": name, "mesh": i, "translation": [2.0 * i, 0, 0]})
        doc["scenes"][0]["nodes"].append(i)
    write(p, json.dumps(doc))


# ---- 1. -o and what it points at, for every verb that writes ----
recipe = path("recipe.json")
write(recipe, json.dumps({"mesh": "tube", "channels": [{"name": "taper_top", "op": "taper", "axis": "y", "scale": 0.3}]}))
verbs = {
    "import": (["import", example], ".morph"),
    "play": (["play", example, "--weights", "bend=1"], ".json"),
    "export": (["export", example, "--no-sidecar"], ".glb"),
    "bake": (["bake", example, "--recipe", recipe], ".morph"),
    "info": (["info", example], ".txt"),
}
for verb, (args, ext) in verbs.items():
    # The input itself: refused before anything is read, the file unchanged.
    before = digest(example)
    expect(verb + ": -o the input itself is refused", args + ["-o", example], 2, err_has="refusing to overwrite the input")
    check(verb + ": the input is unchanged", digest(example) == before)
    # A symbolic link to the input is the input too.
    link_in = path(verb + "_in_link" + ext)
    os.symlink(example, link_in)
    expect(verb + ": -o a link to the input is refused", args + ["-o", link_in], 2, err_has="refusing to overwrite the input")
    os.unlink(link_in)
    # A symbolic link to a regular file: the file is replaced, the link stays a link.
    target = path(verb + "_target" + ext)
    write(target, "old")
    link = path(verb + "_link" + ext)
    os.symlink(os.path.basename(target), link)
    expect(verb + ": -o a symlink writes through it", args + ["-o", link], 0)
    check(verb + ": the symlink stays a symlink", os.path.islink(link) and os.readlink(link) == os.path.basename(target))
    with open(target, "rb") as f:
        check(verb + ": its target got the output", f.read() != b"old")
    # A dangling symbolic link: its target is created.
    dangling = path(verb + "_dangling" + ext)
    made = path(verb + "_made" + ext)
    os.symlink(os.path.basename(made), dangling)
    expect(verb + ": -o a dangling symlink creates its target", args + ["-o", dangling], 0)
    check(verb + ": dangling link kept, target created", os.path.islink(dangling) and os.path.isfile(made))
    # A FIFO: written directly (a reader gets the bytes), still a FIFO afterwards.
    fifo = path(verb + "_fifo" + ext)
    os.mkfifo(fifo)
    got = []
    reader = threading.Thread(target=lambda: got.append(open(fifo, "rb").read()), daemon=True)
    reader.start()
    expect(verb + ": -o a FIFO writes into it", args + ["-o", fifo], 0)
    reader.join(30)
    check(verb + ": the FIFO is still a FIFO and its reader got the output",
          stat.S_ISFIFO(os.lstat(fifo).st_mode) and got and len(got[0]) > 0)
    # A directory is an error; nothing is created inside it.
    d = path(verb + "_dir")
    os.mkdir(d)
    expect(verb + ": -o a directory is an error", args + ["-o", d], 1, err_has="is a directory")
    check(verb + ": nothing written into the directory", os.listdir(d) == [])
    # Device twins: a null device takes the output and stays a device; a full device fails.
    if os.geteuid() == 0:
        null, full = path(verb + "_null" + ext), path(verb + "_full" + ext)
        os.mknod(null, 0o666 | stat.S_IFCHR, os.makedev(1, 3))
        os.mknod(full, 0o666 | stat.S_IFCHR, os.makedev(1, 7))
        expect(verb + ": -o a null device succeeds", args + ["-o", null], 0)
        check(verb + ": the null device is still a device", stat.S_ISCHR(os.lstat(null).st_mode))
        expect(verb + ": -o a full device fails", args + ["-o", full], 1, err_has="No space left")
        check(verb + ": the full device is still a device", stat.S_ISCHR(os.lstat(full).st_mode))
    else:
        skip(verb + ": device twins", "mknod needs root")
    leftovers = [n for n in os.listdir(work) if ".tmp." in n or ".bak." in n]
    check(verb + ": no temporary files left", not leftovers, str(leftovers))

# Standard output for streams.
rc, out, err = expect("play -o - writes the frame to standard output", ["play", example, "-o", "-"], 0)
check("play -o -: stdout is the JSON frame", rc == 0 and json.loads(out)["meshes"][0]["name"] == "tube")
rc, out, err = expect("play --format obj -o -", ["play", example, "--format", "obj", "-o", "-"], 0)
check("play --format obj -o -: OBJ on stdout", out.startswith("# morphkit play") and "\nv " in out)
rc, out, err = expect("info --json -o -", ["info", example, "--json", "-o", "-"], 0)
check("info --json on stdout parses", rc == 0 and json.loads(out)["meshes"][0]["name"] == "tube")
expect("import -o - is refused (a blob is not a stream)", ["import", example, "-o", "-"], 2, err_has="standard output")

# Multi-file outputs are all or nothing.
expect("export with an impossible sidecar fails", ["export", example, "-o", path("o.glb"), "--sidecar", "/nonexistent/x.json"], 1)
check("... and leaves no o.glb behind", not os.path.exists(path("o.glb")))
write(path("keep.glb"), "previous")
os.mkdir(path("sidecar_dir.json"))
expect("export whose sidecar is a directory fails", ["export", example, "-o", path("keep.glb"), "--sidecar", path("sidecar_dir.json")], 1)
with open(path("keep.glb")) as f:
    check("... and leaves the existing glTF as it was", f.read() == "previous")
expect("export with the sidecar named like the glTF is refused",
       ["export", example, "-o", path("same.glb"), "--sidecar", path("same.glb")], 2)
expect("export writes both files", ["export", example, "-o", path("both.glb")], 0)
check("... the glTF and its default sidecar", os.path.isfile(path("both.glb")) and os.path.isfile(path("both.channels.json")))

# ---- 4/5. Silent options and names that do not match the content ----
expect("import -o o.glb is refused (import writes .morph)", ["import", example, "-o", path("o.glb")], 2, err_has="must end in .morph")
check("... nothing written", not os.path.exists(path("o.glb")))
expect("play -o x.txt is refused", ["play", example, "-o", path("x.txt")], 2, err_has=".json or .obj")
expect("export -o x.morph is refused", ["export", example, "-o", path("x.morph")], 2, err_has=".glb or .gltf")
expect("import --channels on a non-glTF input is an error", ["import", example, "--channels", path("broken.json"), "-o", path("c.morph")],
       2, err_has="glTF input only")
expect("import --stacking sequential of a .morph", ["import", example, "--stacking", "sequential", "-o", path("seq.morph")], 0)
rc, out, err = run("info", path("seq.morph"), "--json")
check("... is stored (info says sequential)", rc == 0 and json.loads(out)["meshes"][0]["stacking"] == "sequential")
for spec, what in [("=1", "has no channel name"), ("bend=1,,bulge=1", "empty"), ("bend=", "finite number"),
                   ("bend=nan", "finite number"), ("bend", "NAME=VALUE"), ("nope=1", "the channels are 'bulge', 'bend'")]:
    expect("--weights '%s' is an error" % spec, ["play", example, "--weights", spec, "-o", path("w.json")], 2, err_has=what)
check("no frame written after --weights errors", not os.path.exists(path("w.json")))

# ---- 2. Channel names over primitives and nodes ----
two_nodes = path("two_nodes.gltf")
plain_gltf(two_nodes, node_names=("left", "right"), with_targets=True, target_names=("smile",))
expect("a name on two nodes is an error listing them", ["play", two_nodes, "--weights", "smile=1", "-o", path("n.json")], 2,
       err_has="'left', 'right'")
rc, out, err = expect("NODE/CHANNEL resolves it", ["play", two_nodes, "--weights", "right/smile=1", "--space", "local", "-o", path("n.json")], 0)
if rc == 0:
    d = json.load(open(path("n.json")))
    w = {m["name"]: m["channels"][0]["weight"] for m in d["meshes"]}
    check("... only that node's channel is set", w == {"left": 0, "right": 1}, str(w))
if have_corpus:
    stress = os.path.join(corpus, "gltf/MorphStressTest/glTF/MorphStressTest.gltf")
    rc, out, err = expect("a glTF mesh's channel name reaches every primitive",
                          ["play", stress, "--weights", "Key 1=1", "--space", "local", "-o", path("stress.json")], 0)
    rc0, _, _ = run("play", stress, "--space", "local", "-o", path("stress0.json"))
    if rc == 0 and rc0 == 0:
        a, b = json.load(open(path("stress.json")))["meshes"], json.load(open(path("stress0.json")))["meshes"]
        check("... both primitives have Key 1 = 1", all(m["channels"][0]["weight"] == 1 for m in a))
        check("... and primitive 1 (where the shape is) moved", a[1]["positions"] != b[1]["positions"])
else:
    skip("MorphStressTest weights", "corpus not found")

# ---- 6. External glTF buffers resolve against the glTF's folder only (checked by the importer tests) ----
# ---- 7. Bake on a plain mesh ----
plain = path("plain.gltf")
plain_gltf(plain, node_names=("ico",))
ico_recipe = path("ico_recipe.json")
write(ico_recipe, json.dumps({"mesh": "ico", "channels": [{"name": "squash", "op": "taper", "axis": "z", "scale": 0.5}]}))
rc, out, err = expect("bake on a mesh without morph targets", ["bake", plain, "--recipe", ico_recipe, "-o", path("ico.morph")], 0)
rc, out, err = run("info", path("ico.morph"), "--json")
check("... gives the mesh with its baked channel", rc == 0 and json.loads(out)["meshes"][0]["channels"][0]["name"] == "squash")
wrong = path("wrong_recipe.json")
write(wrong, json.dumps({"mesh": "icosahedron", "channels": [{"name": "s", "op": "taper", "axis": "z", "scale": 0.5}]}))
expect("a recipe naming a missing mesh lists the meshes", ["bake", plain, "--recipe", wrong, "-o", path("w.morph")], 1,
       err_has='the meshes are "ico"')
rc, out, err = expect("import skips a plain mesh with a warning naming it", ["import", plain, "--all-meshes", "-o", path("p.morph")], 0)
rc, out, err = run("import", two_nodes, "-o", path("t.morph"))
check("import of meshes with targets prints no skipped-mesh warning", rc == 0 and "no morph targets" not in err, err)

# Outlier blocks: deltas of 0.5 at a tolerance of 1e-7 are 2.5e6 steps (step = 1e-7 / (0.5 + 2^-8)),
# beyond the int16 offsets of an entry's head but below 2^23 steps, and spread over 1500 steps: the
# block is packed around int32 position offsets (a WIDE entry), and info counts it (text and
# --json, whole and per mesh). At 1e-8 the same deltas are 2.5e7 steps, beyond what float32 holds
# exactly: the block is stored as float32.
offset_gltf = path("offset.gltf")
plain_gltf(offset_gltf, with_targets=True, delta=[0, 0, 0.5, 0, 0, 0.5001, 0, 0, 0.5002, 0, 0, 0.5003])
rc, out, err = expect("import with a tolerance the block's offsets exceed int16 at",
                      ["import", offset_gltf, "--tolerance", "1e-7", "-o", path("offset.morph")], 0)
check("... reports one wide block", "0 of 1 blocks float, 1 wide" in out, out)
rc, out, err = run("info", path("offset.morph"), "--json")
info = json.loads(out) if rc == 0 else {}
check("info --json counts the wide entry", info.get("wide_entries") == 1 and info.get("float_entries") == 0
      and info["meshes"][0]["wide_entries"] == 1 and info["meshes"][0]["float_entries"] == 0, out)
rc, out, err = run("info", path("offset.morph"))
check("info's text counts it", "(0 float blocks, 1 wide)" in out
      and "(0 float in quantized targets, 1 wide)" in out, out)
rc, out, err = expect("import with a tolerance the deltas exceed 2^23 steps at",
                      ["import", offset_gltf, "--tolerance", "1e-8", "-o", path("beyond.morph")], 0)
check("... reports one float block, none wide", "1 of 1 blocks float, 0 wide" in out, out)

# ---- 8. Sizes ----
for args, what in [(["--vertices", "5000000000"], "out of range"), (["--vertices", "-5"], "not a whole number"),
                   (["--density", "0.5"], "out of range"), (["--threads", "0"], "out of range"),
                   (["--channels", "10", "--active", "11"], "more than --channels"),
                   (["--vertices", "100000000", "--channels", "100000", "--active", "100000"], "needs about")]:
    expect("bench %s is refused" % " ".join(args), ["bench"] + args, 2, err_has=what)

# ---- 3/13. Conformance: static state, meshes without channels, manifests ----
static_case = path("static_case.json")
play_rc, _, _ = run("play", example, "--space", "local", "-o", path("static_with_normals.obj"))
write(path("static.obj"), "".join(l for l in open(path("static_with_normals.obj")) if not l.startswith("vn ")))
write(static_case, json.dumps({"version": 1, "cases": [{"name": "static", "source": example, "format": "fbx",
      "reference": {"kind": "obj", "space": "mesh-local", "match": "vertices", "tolerance": 1e-5},
      "frames": [{"time": None, "file": path("static.obj")}]}]}))
rc, out, err = expect("a \"time\": null frame is the static state (default weights, no clip)", ["conform", static_case, "--precision", "float"], 0)
check("conform prints 'normal -' when the reference has no normals", " normal -" in out, out)
write(path("not_manifest.json"), json.dumps({"hello": 1}))
expect("conform on a file that is not a manifest says so", ["conform", path("not_manifest.json")], 1, err_has="not a conformance manifest")
expect("conform --case matching nothing says so", ["conform", static_case, "--case", "zzz"], 1, err_has="matches none")

# ---- Messages, help, exit codes ----
expect("unknown verb: exit 2", ["frobnicate"], 2, err_has="unknown verb")
expect("unknown option: exit 2", ["info", example, "--frobnicate"], 2, err_has="unknown option '--frobnicate'")
expect("a bad choice names the value and the accepted ones", ["play", example, "--stacking", "sideways", "-o", path("s.json")], 2,
       err_has='"sideways" is not additive|sequential')
expect("play without -o says what is missing", ["play", example], 2, err_has="missing -o")
expect("an option given twice is an error", ["play", example, "--time", "1", "--time", "2", "-o", path("t.json")], 2, err_has="given twice")
expect("a directory as input says so", ["info", work], 1, err_has="is a directory")
write(path("empty.fbx"), "")
expect("an empty input says so", ["info", path("empty.fbx")], 1, err_has="empty file")
rc, out, err = expect("a failed import prints no warning count first", ["import", path("missing.fbx"), "-o", path("m.morph")], 1)
check("... (nothing but the error)", "warning" not in err and err.count("missing.fbx") == 1, err)
rc, out, err = expect("play with --weights reports what was played", ["play", example, "--weights", "bend=1", "-o", path("p.json")], 0)
check("... (default weights, then --weights)", "then --weights" in out and "rest-pose" not in out, out)
rc, out, err = expect("play with --time reports the clip and time", ["play", example, "--time", "0.5", "-o", path("p.json")], 0)
check("... (clip 'wave' at 0.5 s)", "clip 'wave' at 0.5 s" in out, out)
expect("--version", ["--version"], 0, out_has="format v")
rc, out, _ = run("--help")
verbs_all = ["import", "info", "play", "bake", "export", "conform", "bench"]
check("morphkit --help lists every verb", rc == 0 and all("  %s " % v in out for v in verbs_all), out)
for v in verbs_all:
    rc1, h1, _ = run("help", v)
    rc2, h2, _ = run(v, "--help")
    check("help %s == %s --help, exit 0" % (v, v), rc1 == 0 and rc2 == 0 and h1 == h2 and h1.startswith("usage: morphkit " + v))
    check("help %s documents exit codes" % v, "exit status: 0 success, 1 failure, 2 usage error" in h1)
    # docs/cli.md quotes each verb's help exactly.
    docs = open(os.path.join(root, "docs", "cli.md")).read()
    check("docs/cli.md quotes 'morphkit help %s' exactly" % v, "```\n" + h1 + "```" in docs,
          "regenerate the blocks with scripts/update-cli-doc")
# Progress goes to a terminal only: piped, bench prints none.
rc, out, err = run("bench", "--vertices", "5000", "--channels", "4", "--active", "2", "--frames", "3")
check("bench piped prints no progress", rc == 0 and err == "", err)

if os.path.exists("/usr/bin/script"):
    cmd = "'%s' bench --vertices 300000 --channels 10 --active 3 --frames 20" % mk
    p = subprocess.run(["script", "-qec", cmd, "/dev/null"], capture_output=True, text=True, timeout=300)
    check("bench on a terminal shows progress", "building the synthetic asset" in p.stdout and "timing passes" in p.stdout,
          p.stdout[-500:])
    p = subprocess.run(["script", "-qec", cmd + " --quiet", "/dev/null"], capture_output=True, text=True, timeout=300)
    check("--quiet silences progress, not results", "timing passes" not in p.stdout and "ns_per_frame" in p.stdout,
          p.stdout[-500:])
else:
    skip("progress on a terminal", "script(1) not found")

finish()
