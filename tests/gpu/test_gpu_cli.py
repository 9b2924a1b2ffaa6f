#!/usr/bin/env python3
"""The GPU path through the command (docs/gpu.md): `play --gpu` and `frames --gpu` give the
CPU's frame within docs/gpu.md's tolerance (nlerp, slerp, sequential, surface normals, forced
weights beyond the keys), `bench --gpu --json` runs and reports its keys (no speed asserted),
samples/gpu_vulkan agrees with the CPU, and without a Vulkan driver --gpu fails with a clear
message instead of falling back. The validation layer is on (MORPHKIT_VK_VALIDATION=1): a
message fails the command. Everything skips where no Vulkan device exists.

usage: test_gpu_cli.py MORPHKIT MAKE_EXAMPLE GPU_SAMPLE"""
import json, math, os, re, sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "cli"))
from cli_check import check, finish, runner, scratch, skip

mk, make_example, sample = sys.argv[1], sys.argv[2], sys.argv[3]
os.environ["MORPHKIT_VK_VALIDATION"] = "1"
work = scratch("mk_gpu_cli_")
run = runner(mk, timeout=300)
example = os.path.join(work, "example.morph")
rc, out, err = runner(make_example)(example)
check("make_example", rc == 0, err)

probe = os.path.join(work, "probe.json")
rc, out, err = run("play", example, "-o", probe, "--gpu")
if rc != 0 and ("no Vulkan" in err or "without the GPU path" in err or "validation layer" in err and "not installed" in err):
    skip("gpu cli", "no usable Vulkan device: " + err.strip())
    finish()


def frame(*extra, asset=example):
    path = os.path.join(work, "frame.json")
    rc, _, err = run("play", asset, "-o", path, *extra)
    if rc:
        return None, err
    with open(path) as f:
        return json.load(f), err


def diagonal(positions):
    lo = [min(positions[k::3]) for k in range(3)]
    hi = [max(positions[k::3]) for k in range(3)]
    return math.sqrt(sum((h - l) ** 2 for l, h in zip(lo, hi)))


def angle(a, b):
    c = (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])
    return math.atan2(math.sqrt(sum(x * x for x in c)), sum(x * y for x, y in zip(a, b)))


def compare(name, *extra, asset=example):
    cpu, err_cpu = frame(*extra, asset=asset)
    gpu, err_gpu = frame("--gpu", *extra, asset=asset)
    if not check(name + ": both play", cpu is not None and gpu is not None, err_cpu + err_gpu):
        return
    worst_p = worst_n = 0.0
    for mc, mg in zip(cpu["meshes"], gpu["meshes"]):
        p, q = mc["positions"], mg["positions"]
        d = max(diagonal(p), 1e-3)
        worst_p = max(worst_p, max(abs(x - y) for x, y in zip(p, q)) / d)
        if "normals" in mc:
            n, m = mc["normals"], mg["normals"]
            worst_n = max(worst_n, max(angle(n[i:i + 3], m[i:i + 3]) for i in range(0, len(n), 3)))
    check(name + ": within 1e-6 of the diagonal and 1e-4 rad (positions %.3g, normals %.3g rad)" % (worst_p, worst_n),
          worst_p <= 1e-6 and worst_n <= 1e-4)
    check(name + ": the device is named on stderr", "GPU path on" in err_gpu, err_gpu)


compare("clip", "--time", "0.7")
compare("slerp", "--time", "1.3", "--normals", "slerp")
compare("sequential", "--time", "1.3", "--stacking", "sequential")
compare("surface", "--time", "0.4", "--normals", "surface")
compare("beyond the keys", "--weights", "bend=1.6,bulge=-0.7", "--normals", "slerp")

# Every sample recipe baked onto the example (the shell onto the ball), every channel weighted
# (some beyond their last in-between), both normal modes.
recipes = os.path.join(os.environ.get("MORPHKIT_SOURCE_ROOT", "."), "samples", "recipes")
ball = os.path.join(work, "ball.morph")
runner(make_example)("--ball", ball)
for recipe in sorted(f for f in os.listdir(recipes) if f.endswith(".json")):
    baked = os.path.join(work, "baked_" + recipe.replace(".json", ".morph"))
    source = ball if recipe == "shell.json" else example
    rc, _, err = run("bake", source, "--recipe", os.path.join(recipes, recipe), "-o", baked, "--quiet")
    if not check("bake " + recipe, rc == 0, err):
        continue
    rc, out, err = run("info", baked, "--json")
    names = [c["name"] for m in json.loads(out)["meshes"] for c in m["channels"]] if rc == 0 else []
    weights = ",".join("%s=%.2f" % (n, 0.3 + (0.37 * i) % 1.5) for i, n in enumerate(names))
    compare("baked " + recipe, "--weights", weights, asset=baked)
    compare("baked " + recipe + ", slerp", "--weights", weights, "--normals", "slerp", asset=baked)

# frames --gpu writes the frames the CPU writes, within the tolerance (the .mkf frames compared by
# conform against the CPU's, from the same manifest).
cpu_dir, gpu_dir = os.path.join(work, "frames_cpu"), os.path.join(work, "frames_gpu")
rc1, _, e1 = run("frames", example, "-o", cpu_dir, "--frames", "4")
rc2, _, e2 = run("frames", example, "-o", gpu_dir, "--frames", "4", "--gpu")
check("frames --gpu runs", rc1 == 0 and rc2 == 0, e1 + e2)
if rc1 == 0 and rc2 == 0:
    rc, out, err = run("conform", os.path.join(gpu_dir, "manifest.json"))
    check("frames --gpu: the GPU's frames conform on the CPU", rc == 0, out[-800:] + err)
    rc, out, err = run("conform", os.path.join(cpu_dir, "manifest.json"), "--gpu")
    check("conform --gpu: the CPU's frames conform on the GPU", rc == 0, out[-800:] + err)

rc, out, err = run("bench", example, "--gpu", "--json", "--frames", "5", "--quiet")
doc = json.loads(out) if rc == 0 and out.strip().startswith("{") else {}
keys = ("device", "gpu_ns_per_frame", "gpu_ns_per_frame_positions", "cpu_record_ns_per_frame", "upload_ms",
        "bytes_per_frame", "gpu_copy_gb_per_s", "gpu_bound_ns", "gpu_ratio_to_bound", "cpu_ns_per_frame",
        "gpu_speedup_vs_cpu")
check("bench --gpu --json reports its keys", all(k in doc for k in keys), out + err)
check("bench --gpu: times are positive", all(doc.get(k, 0) > 0 for k in keys[1:3]), out)

rc, out, err = runner(sample)(example)
m = re.search(r"largest difference: positions \S+ \((\S+) of the bounding-box diagonal\), normals (\S+) rad", out)
check("samples/gpu_vulkan agrees with the CPU", rc == 0 and m and float(m.group(1)) <= 1e-6 and float(m.group(2)) <= 1e-4,
      out + err)

# Without a driver --gpu fails, names the cause, and writes nothing.
env_icd = os.environ.get("VK_ICD_FILENAMES")
os.environ["VK_ICD_FILENAMES"] = os.path.join(work, "no_such_icd.json")
missing = os.path.join(work, "missing.json")
rc, out, err = run("play", example, "-o", missing, "--gpu")
check("no driver: play --gpu fails with a message", rc == 1 and "Vulkan" in err and not os.path.exists(missing), err)
if env_icd is None:
    del os.environ["VK_ICD_FILENAMES"]
else:
    os.environ["VK_ICD_FILENAMES"] = env_icd
finish()
