#!/usr/bin/env python3
"""Conformance as a product:
  - golden frames (`morphkit frames`) for every corpus source: `conform` passes on them, the
    runtime-only sample samples/golden_check passes on them, and a perturbed copy fails both;
  - tolerances that scale: a large-coordinate asset (coordinates up to 234, 25 active shapes)
    whose reference is computed here in double precision, independently of morphkit, cannot meet
    an absolute 1e-5 in float32, passes with a relative tolerance (and says so), and a copy with
    one vertex moved by 1e-3 fails both;
  - a manifest with a broken field is refused naming the case and the field.
usage: test_conformance.py MORPHKIT GOLDEN_CHECK MAKE_EXAMPLE"""
import base64, json, math, os, random, shutil, struct, subprocess, sys, tempfile

mk, golden_check, make_example = sys.argv[1], sys.argv[2], sys.argv[3]
from cli_check import check, corpus, finish, have_corpus, scratch, skip

work = scratch("mk_conformance_")


def run(*args):
    p = subprocess.run([str(a) for a in args], capture_output=True, text=True, timeout=600)
    return p.returncode, p.stdout, p.stderr


def perturb_mkf(path):
    """Moves the first vertex of the first mesh by 1e-3 (x) in a binary frame."""
    b = bytearray(open(path, "rb").read())
    channels = struct.unpack_from("<I", b, 16)[0]
    at = 48 + 4 * channels + 16
    x = struct.unpack_from("<f", b, at)[0]
    struct.pack_into("<f", b, at, x + 1e-3)
    open(path, "wb").write(b)


def perturb_json(path):
    d = json.load(open(path))
    d["meshes"][0]["positions"][0] += 1e-3
    json.dump(d, open(path, "w"))


# ---- golden frames for every corpus source (and the example) ----
sources = []
ex = os.path.join(work, "example.morph")
subprocess.run([make_example, ex], check=True, capture_output=True)
sources.append(("example", ex))
if have_corpus:
    seen = set()
    for case in json.load(open(os.path.join(corpus, "cases.json")))["cases"]:
        if case["source"] not in seen:
            seen.add(case["source"])
            sources.append((case["name"], os.path.join(corpus, case["source"])))
else:
    skip("corpus sources", "corpus not found")
for i, (name, src) in enumerate(sources):
    out = os.path.join(work, "golden_%d" % i)
    modes = ["--stacking", "sequential", "--normals", "slerp"] if i % 3 == 1 else []
    rc, o, e = run(mk, "frames", src, "-o", out, "--frames", "4", *modes)
    if rc != 0:
        check("%s: morphkit frames" % name, False, e)
        continue
    rc1, o1, e1 = run(mk, "conform", os.path.join(out, "manifest.json"))
    rc2, o2, e2 = run(golden_check, out)
    check("%s: conform and golden_check pass on its golden frames" % name, rc1 == 0 and rc2 == 0, o1 + e1 + o2 + e2)
# A perturbed copy fails both.
src_dir = os.path.join(work, "golden_0")
if os.path.isdir(src_dir):
    bad = os.path.join(work, "golden_bad")
    shutil.copytree(src_dir, bad)
    perturb_mkf(os.path.join(bad, "frame_001.mkf"))
    perturb_json(os.path.join(bad, "frame_001.json"))
    rc1, o1, _ = run(mk, "conform", os.path.join(bad, "manifest.json"))
    rc2, o2, _ = run(golden_check, bad)
    check("a golden frame with one vertex moved by 1e-3 fails conform (both formats)",
          rc1 == 1 and o1.count("FAIL") == 2 and "frame_001" in o1, o1)
    check("... and fails golden_check", rc2 == 1, o2)

# ---- tolerances that scale ----
random.seed(5)
N = 40
base = []
for j in range(N):
    for i in range(N):
        base.append((234.0 * i / (N - 1), 117.0 + 60.0 * math.sin(i * 0.3) * math.cos(j * 0.2), 234.0 * j / (N - 1)))
tris = []
for j in range(N - 1):
    for i in range(N - 1):
        a = j * N + i
        tris += [a, a + 1, a + N + 1, a, a + N + 1, a + N]
targets, weights = [], []
for k in range(25):
    cx, cz, r = random.uniform(0, 234), random.uniform(0, 234), random.uniform(40, 90)
    d = []
    for (x, y, z) in base:
        f = max(0.0, 1 - math.hypot(x - cx, z - cz) / r)
        d.append((random.uniform(-0.3, 0.3) * f, random.uniform(5, 20) * f, random.uniform(-0.3, 0.3) * f))
    targets.append(d)
    weights.append(round(random.uniform(0.2, 0.95), 4))
# The reference in double precision, straight from the glTF definition: base + sum w_k delta_k,
# with the same float32 inputs the file stores.
f32 = lambda v: struct.unpack("<f", struct.pack("<f", v))[0]
ref = []
for v in range(len(base)):
    p = [f32(c) for c in base[v]]
    for k in range(25):
        for c in range(3):
            p[c] += f32(weights[k]) * f32(targets[k][v][c])
    ref += p
buf = b"".join(struct.pack("<3f", *p) for p in base) + struct.pack("<%dI" % len(tris), *tris)
views = [{"buffer": 0, "byteOffset": 0, "byteLength": 12 * len(base)},
         {"buffer": 0, "byteOffset": 12 * len(base), "byteLength": 4 * len(tris)}]
accessors = [{"bufferView": 0, "componentType": 5126, "count": len(base), "type": "VEC3",
              "min": [min(p[c] for p in base) for c in range(3)], "max": [max(p[c] for p in base) for c in range(3)]},
             {"bufferView": 1, "componentType": 5125, "count": len(tris), "type": "SCALAR"}]
tgt_json = []
for d in targets:
    off = len(buf)
    buf += b"".join(struct.pack("<3f", *x) for x in d)
    views.append({"buffer": 0, "byteOffset": off, "byteLength": 12 * len(base)})
    accessors.append({"bufferView": len(views) - 1, "componentType": 5126, "count": len(base), "type": "VEC3",
                      "min": [min(x[c] for x in d) for c in range(3)], "max": [max(x[c] for x in d) for c in range(3)]})
    tgt_json.append({"POSITION": len(accessors) - 1})
gltf = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": len(buf), "uri": "data:application/octet-stream;base64,"
        + base64.b64encode(buf).decode()}], "bufferViews": views, "accessors": accessors,
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "targets": tgt_json}], "weights": weights}],
        "nodes": [{"name": "terrain", "mesh": 0}], "scenes": [{"nodes": [0]}], "scene": 0}
json.dump(gltf, open(os.path.join(work, "large.gltf"), "w"))
frame = {"meshes": [{"label": "terrain", "node": 0, "mesh": 0, "primitive": 0, "weights": weights, "positions": ref}]}
json.dump(frame, open(os.path.join(work, "large_ref.json"), "w"))
perturbed = json.loads(json.dumps(frame))
perturbed["meshes"][0]["positions"][3 * 777 + 1] += 1e-3
json.dump(perturbed, open(os.path.join(work, "large_ref_moved.json"), "w"))


def manifest(name, reference, tolerance, relative=None):
    ref_obj = {"kind": "three-json", "space": "mesh-local", "match": "vertices", "tolerance": tolerance}
    if relative is not None:
        ref_obj["relative_tolerance"] = relative
    path = os.path.join(work, name + ".json")
    json.dump({"version": 1, "cases": [{"name": name, "source": "large.gltf", "format": "gltf", "reference": ref_obj,
                                        "frames": [{"time": None, "file": reference}]}]}, open(path, "w"))
    return path


rc, o, e = run(mk, "conform", manifest("absolute", "large_ref.json", 1e-5), "--precision", "float", "--json")
d = json.loads(o) if o.strip().startswith("{") else {"frames": [{}]}
err = d["frames"][0].get("position_error", 0)
check("at coordinates up to 234 with 25 shapes float32 cannot meet 1e-5 absolute (error %.3g)" % err,
      rc == 1 and err > 1e-5 and err < 1e-3, o + e)
rc, o, e = run(mk, "conform", manifest("relative", "large_ref.json", 1e-5, 1e-6), "--precision", "float", "--json")
d = json.loads(o) if o.strip().startswith("{") else {"frames": [{}]}
check("a relative tolerance (1e-6 x diagonal) passes it and says which tolerance passed",
      rc == 0 and d["frames"][0].get("passed_by") == "relative_tolerance", o + e)
rc, o, e = run(mk, "conform", manifest("moved", "large_ref_moved.json", 1e-5, 1e-6), "--precision", "float")
check("a copy with one vertex moved by 1e-3 fails both tolerances", rc == 1 and "FAIL" in o, o + e)
rc, o, e = run(mk, "conform", manifest("largest", "large_ref.json", 0, 1e-6), "--precision", "float")
check("relative_to defaults to the diagonal; relative_tolerance alone is a valid case", rc == 0, o + e)

# ---- normal quality of the example's golden frames (bulge and bend combined) ----
golden_example = os.path.join(work, "golden_0", "manifest.json")
rc, o, e = run(mk, "conform", golden_example, "--normal-quality", "--json")
d = json.loads(o) if o.strip().startswith("{") else {}
q = (d.get("normal_quality") or [{}])[0]
print("example normal quality:", json.dumps(q))
check("conform --normal-quality measures every mode over the moved vertices of the frames",
      rc == 0 and q.get("measured", 0) > 0 and all(m in q for m in ("nlerp", "slerp", "surface", "base")), o + e)
check("surface normals meet the evaluated surface (max < 1e-3 deg); nlerp does not where shapes combine",
      q.get("surface", {}).get("max_deg", 1) < 1e-3 and q.get("nlerp", {}).get("mean_deg", 0) > 0.1
      and q.get("base", {}).get("mean_deg", 0) > q.get("nlerp", {}).get("mean_deg", 1), json.dumps(q))
rc, o, e = run(mk, "conform", golden_example, "--normal-quality")
check("conform --normal-quality prints one line per case",
      rc == 0 and o.count("normal quality over") == len(d.get("normal_quality", [])) > 0, o + e)

# ---- manifests are checked ----
bad_manifest = os.path.join(work, "bad.json")
json.dump({"version": 1, "cases": [{"name": "x", "source": "large.gltf", "format": "gltf",
                                    "reference": {"kind": "three-json", "space": "sideways", "match": "vertices",
                                                  "tolerance": 1e-5}, "frames": [{"time": None, "file": "a.json"}]}]},
          open(bad_manifest, "w"))
rc, o, e = run(mk, "conform", bad_manifest)
check("a broken field is refused naming the case and the field", rc == 1 and "cases[0] 'x'.reference" in e and "space" in e, e)

shutil.rmtree(work, ignore_errors=True)
finish()
