#!/usr/bin/env python3
"""No call circle between source files: reads the object files of a build and fails when a
source file uses (calls, or reads or writes a variable of) another that, directly or through
others, uses it back. Usage: check_calls.py BUILD_DIR (meson test passes the build).

Which objects: every object in the build's compile_commands.json whose source is the project's
own code, mapped back to that source (a source compiled into several targets is one file). Left
out are sources under tests/ (test programs, their libraries and the fuzzers) and objects of
any target defined under tests/ (a test that compiles a library source in), sources outside
the source tree or inside the build folder (generated), and subprojects. Libraries, tools and
samples are all read, and circles across libraries count like circles inside one.

The graph: `nm -A -P -g` lists each object's external symbols. A file A uses file B when A has
a symbol undefined (U, w, v) that B defines strongly (T, D, B, R, ...; weak definitions, the C++
inline functions and template instances every object using them carries, are not counted).
When several files define the symbol, the one in A's own target is taken, else all of them.
Symbols no project object defines (the C library, libdeflate, Vulkan, the sanitizers) are left
out. Each circle is printed as A -> B -> ... -> A with the symbols each step uses; for every
use that closes a circle the shortest such circle is shown. No use between files at all fails
too: nm read no symbols (LTO objects, for one, want NM=gcc-nm).

An object of a target that is not built fails the check: the test's `depends:` in
tests/meson.build must list every library and program read here (meson test builds only
those)."""
import json, os, subprocess, sys

from structure import check, circles, finish

if len(sys.argv) != 2:
    sys.exit("usage: check_calls.py BUILD_DIR")
build = os.path.realpath(sys.argv[1])
root = os.path.realpath(os.environ.get("MORPHKIT_SOURCE_ROOT") or
                        os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", ".."))


def inside(path, folder):
    return path == folder or path.startswith(folder + os.sep)


# ---- objects and the sources they come from ----
targets = {}   # a target's private folder (relative to the build) -> where it is defined
for t in json.load(open(os.path.join(build, "meson-info", "intro-targets.json"))):
    for f in t["filename"]:
        targets[os.path.relpath(f, build) + ".p"] = (t["name"], t.get("subproject"),
                                                     os.path.relpath(t["defined_in"], root))
objects = {}   # object path (relative to the build) -> (source relative to the root, target folder)
for entry in json.load(open(os.path.join(build, "compile_commands.json"))):
    source = os.path.realpath(os.path.join(entry["directory"], entry["file"]))
    output = os.path.normpath(os.path.join(os.path.relpath(entry["directory"], build), entry["output"]))
    parts = output.split(os.sep)   # the object lies in its target's private folder, NAME.p
    folder = next((os.sep.join(parts[:i + 1]) for i, p in enumerate(parts) if p.endswith(".p")), None)
    target = targets.get(folder)
    if target is None or target[1] or inside(target[2], "tests"):
        continue
    if inside(source, build) or not inside(source, root):
        continue
    source = os.path.relpath(source, root)
    if inside(source, "tests") or inside(source, "subprojects"):
        continue
    objects[output] = (source, folder)

missing = sorted("%s (target %s)" % (o, targets[f][0]) for o, (_, f) in objects.items()
                 if not os.path.exists(os.path.join(build, o)))
check("the project's objects are built (%d objects of %d sources)" %
      (len(objects), len({s for s, _ in objects.values()})),
      (["no objects of the project's own code in the build"] if not objects else []) +
      ["%s is not built (build first; meson test builds it only when its target is among the depends of "
       "test('calls') in tests/meson.build)" % m
       for m in missing])
if missing or not objects:
    finish()

# ---- symbols ----
defines, uses = {}, {}   # symbol -> [(source, target folder)]; object -> {symbols}
STRONG = set("TDBRGSC")
names = sorted(objects)
for start in range(0, len(names), 500):
    run = subprocess.run([os.environ.get("NM", "nm"), "-A", "-P", "-g"] + names[start:start + 500],
                         cwd=build, capture_output=True, text=True)
    if run.returncode != 0:
        sys.exit("nm failed: " + run.stderr.strip())
    for line in run.stdout.splitlines():
        where, _, rest = line.partition(": ")
        fields = rest.split()
        if len(fields) < 2 or where not in objects:
            continue
        symbol, kind = fields[0], fields[1]
        if kind in ("U", "w", "v"):
            uses.setdefault(where, set()).add(symbol)
        elif kind in STRONG:
            defines.setdefault(symbol, []).append(objects[where])

graph, via = {}, {}   # source -> {sources it uses}; (a, b) -> {symbols}
for obj, symbols in uses.items():
    a, folder = objects[obj]
    for symbol in symbols:
        owners = defines.get(symbol, [])
        own = [s for s, f in owners if f == folder]
        for b in set(own or [s for s, _ in owners]):
            if b != a:
                graph.setdefault(a, set()).add(b)
                via.setdefault((a, b), set()).add(symbol)

problems = [] if graph else ["nm found no file using another: the objects' symbols were not read"]
for circle in circles({a: sorted(bs) for a, bs in graph.items()}):
    problems.append(" -> ".join(circle))
    for a, b in zip(circle, circle[1:]):
        problems.append("  %s uses %s of %s" % (a, ", ".join(sorted(via[(a, b)])), b))
check("no call circle between source files (%d files, %d uses between them)" %
      (len({s for s, _ in objects.values()}), sum(len(bs) for bs in graph.values())), problems)
finish()
