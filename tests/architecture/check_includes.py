#!/usr/bin/env python3
"""Keeps docs/architecture.md true: reads its table of modules and the folders each may
include from, then checks every C/C++ source of the repository:
  - a quoted #include resolves to a header of the file's own module or of a listed folder;
  - the blob layout (runtime/format.h) is included only by the runtime, the blob writer and
    reader, the GPU path's bindings (gpu/mesh.c) and the blob's own tests (runtime, fuzz, gpu);
  - the runtime includes nothing but C library headers;
  - no two files include each other through a circle, and the modules form no circle;
  - code, build files and docs cite nothing outside the repository (the team's background
    files, issue numbers);
  - every C/C++ source starts with its SPDX licence line (engines copy sources).
Prints one line per check and "N passed, N failed"."""
import os, re, subprocess

from structure import check, circles, finish

root = os.environ.get("MORPHKIT_SOURCE_ROOT") or os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


# ---- the table ----
doc = open(os.path.join(root, "docs", "architecture.md")).read()
modules = {}   # name -> (folder, [allowed folders] or None for anything)
for line in doc.splitlines():
    cells = [c.strip() for c in line.strip().strip("|").split("|")]
    if len(cells) != 4 or not cells[1].startswith("`"):
        continue
    folder = cells[1].strip("`")
    allowed = re.findall(r"`([^`]+/)`", cells[2])
    modules[cells[0]] = (folder, None if "anything" in cells[2] else allowed)
check("docs/architecture.md has the module table", [] if len(modules) >= 10 else ["found %d rows" % len(modules)])


def module_of(path):
    best = None
    for name, (folder, _) in modules.items():
        if path.startswith(folder) and (best is None or len(folder) > len(modules[best][0])):
            best = name
    return best


files = subprocess.run(["git", "-C", root, "ls-files", "--cached", "--others", "--exclude-standard"],
                       capture_output=True, text=True).stdout.split()
if not files:  # not a git checkout: walk the tree
    for d, _, names in os.walk(root):
        if "/build" in d or "/." in d or "node_modules" in d:
            continue
        files += [os.path.relpath(os.path.join(d, n), root) for n in names]
sources = [f for f in files if re.search(r"\.(c|h|cc|cpp)$", f) and os.path.exists(os.path.join(root, f))]
headers = {}
for f in sources:
    if f.endswith(".h"):
        headers.setdefault(os.path.basename(f), []).append(f)


def resolve(src, name):
    """The repository header a quoted include names: beside the source first, else anywhere."""
    local = os.path.normpath(os.path.join(os.path.dirname(src), name))
    if local in sources:
        return local
    cands = headers.get(os.path.basename(name), [])
    return cands[0] if len(cands) == 1 else (sorted(cands, key=lambda c: (module_of(c) != module_of(src), c))[0] if cands else None)


LIBC = {"assert", "float", "limits", "math", "stdalign", "stdbool", "stddef", "stdint", "string", "stdio", "stdlib",
        "errno", "inttypes", "immintrin", "emmintrin", "smmintrin", "arm_neon", "stdatomic"}
GENERATED = {"box_blob.h",          # written by `morphkit embed` in samples/build_time_bake's build
             "morph_eval.spv.inc"}  # the compute shader's SPIR-V, compiled by glslc (gpu/meson.build)
LAYOUT_OK = ("runtime/", "offline/writer.c", "offline/block_mask.c", "offline/reader.c", "gpu/mesh.c", "tests/runtime/",
             "tests/fuzz/", "tests/gpu/")
graph, bad_rule, bad_layout, bad_runtime, unresolved = {}, [], [], [], []
for src in sources:
    mod = module_of(src)
    text = open(os.path.join(root, src), errors="replace").read()
    graph[src] = []
    for m in re.finditer(r'^\s*#\s*include\s*([<"])([^>"]+)[>"]', text, re.M):
        kind, name = m.group(1), m.group(2)
        if kind == "<":
            if mod == "runtime" and os.path.splitext(os.path.basename(name))[0] not in LIBC:
                bad_runtime.append("%s includes <%s>" % (src, name))
            continue
        target = resolve(src, name)
        if target is None:
            if name.endswith(".c") or name in GENERATED:   # a test compiling another source in; build outputs
                continue
            unresolved.append("%s: \"%s\" is no header of the repository" % (src, name))
            continue
        graph[src].append(target)
        if target == "runtime/format.h":
            if not src.startswith(LAYOUT_OK):
                bad_layout.append("%s includes the blob layout (runtime/format.h)" % src)
            continue
        tmod = module_of(target)
        allowed = modules[mod][1] if mod else []
        if mod is None or allowed is None or tmod == mod:
            continue
        tdir = os.path.dirname(target) + "/"
        if not any(tdir.startswith(a) and module_of(a) == tmod for a in allowed):
            bad_rule.append("%s (%s) includes %s (%s), which its row does not list" % (src, mod, target, tmod))
check("every quoted include resolves to a repository header", unresolved)
check("each module includes only from the folders its row lists", bad_rule)
check("only the runtime, the blob writer/reader, the GPU bindings and the blob's tests see runtime/format.h", bad_layout)
check("the runtime includes only C library headers", bad_runtime)

# ---- circles: files, then modules (the calls between files: check_calls.py) ----
check("no include circle between files", [" -> ".join(c) for c in circles(graph)])
mgraph = {}
for src, targets in graph.items():
    a = module_of(src)
    for t in targets:
        b = module_of(t)
        if a and b and a != b and a != "tests":
            mgraph.setdefault(a, set()).add(b)
check("no circle between modules", [" -> ".join(c) for c in circles({k: sorted(v) for k, v in mgraph.items()})])

# ---- licence ----
missing = [f for f in sources if "SPDX-License-Identifier: MIT" not in open(os.path.join(root, f), errors="replace").readline()]
check("every C/C++ source starts with its SPDX licence line", missing)

# ---- self-contained ----
outside = []
pattern = re.compile(r"DESIGN\.md|\bnotes/[a-z-]+\.md|\bnotes A[0-9]|\(notes\b|issue #[0-9]+")
for f in files:
    if f.endswith(".json") or not os.path.exists(os.path.join(root, f)) or f.startswith("tests/architecture/"):
        continue
    if not re.search(r"\.(c|h|cc|cpp|md|build|txt|sh|py)$|^scripts/|^\.ci/", f):
        continue
    for i, line in enumerate(open(os.path.join(root, f), errors="replace"), 1):
        if pattern.search(line):
            outside.append("%s:%d: %s" % (f, i, line.strip()[:100]))
check("code and docs cite nothing outside the repository", outside)

finish()
