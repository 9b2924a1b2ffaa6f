#!/usr/bin/env python3
"""morphkit render on the generated example, checked by its pixels: the silhouette where the
tube is, a shaded (not flat) surface, a diff that lights up only the cell and the place where
one vertex of one target was moved, and bad sizes, paths and inputs refused without output.

usage: test_pictures.py MORPHKIT MAKE_EXAMPLE"""
import base64, json, os, re, struct, subprocess, sys, zlib

mk, make_example = sys.argv[1], sys.argv[2]
from cli_check import check, finish, runner, scratch, skip

work = scratch("mk_pictures_")

run = runner(mk, timeout=120)


def path(name):
    return os.path.join(work, name)


def read_png(p):
    """(width, height, rows of RGB tuples) of an 8-bit RGB or RGBA PNG."""
    data = open(p, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    at, idat = 8, b""
    while at < len(data):
        n, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        if kind == b"IHDR":
            w, h, depth, color = struct.unpack(">IIBB", body[:10])
            assert depth == 8 and color in (2, 6)
            bpp = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
        at += 12 + n
    raw, rows, prev = zlib.decompress(idat), [], bytearray(w * bpp)
    stride = w * bpp
    for y in range(h):
        f, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            if f == 1: line[i] = (line[i] + a) & 255
            elif f == 2: line[i] = (line[i] + b) & 255
            elif f == 3: line[i] = (line[i] + (a + b) // 2) & 255
            elif f == 4:
                pa, pb, pc = abs(b - c), abs(a - c), abs(a + b - 2 * c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append([tuple(line[x * bpp:x * bpp + 3]) for x in range(w)])
        prev = line
    return w, h, rows


BACKGROUND = (38, 40, 45)   # shaded cells (render/sheet.c)

subprocess.run([make_example, path("ex.morph")], check=True, capture_output=True)

# One front view cell of the rest pose: the tube (x in [-0.5, 0.5], y in [0, 2]) stands in the
# middle; the background shows left and right of it.
rc, out, err = run("render", path("ex.morph"), "--weights", "bend=0", "--view", "front", "--size", "200x200",
                   "-o", path("rest.png"))
check("render a rest pose", rc == 0, err)
w, h, px = read_png(path("rest.png"))
check("one cell of 200x200 plus title and gutters", w == 204 and 200 < h < 240, (w, h))
mid = h - 2 - 100   # the cell's vertical middle (cells end 2 pixels above the bottom)
row = px[mid]
covered = [x for x in range(2, 202) if row[x] != BACKGROUND and abs(row[x][0] - row[x][2]) < 40 and row[x][0] > 60]
check("the silhouette is centered and narrower than tall",
      covered and abs((covered[0] + covered[-1]) / 2 - 102) < 4 and 20 < covered[-1] - covered[0] < 100,
      covered[:3] + covered[-3:])
# The light comes from the upper left: the tube's left half is brighter than its right edge.
lum = lambda p: 0.3 * p[0] + 0.59 * p[1] + 0.11 * p[2]
left, right = covered[0] + (covered[-1] - covered[0]) // 3, covered[-1] - 1
check("lit from the left: left third brighter than the right edge", lum(row[left]) > lum(row[right]) + 30,
      (row[left], row[right]))

# A frame with a bend shows the tube elsewhere: the fixed camera keeps motion visible.
rc, out, err = run("render", path("ex.morph"), "--weights", "bend=0;bend=1", "--view", "front", "--size", "160x160",
                   "--columns", "2", "-o", path("two.png"))
w2, h2, px2 = read_png(path("two.png"))
cell = lambda x0: [px2[y][x] != BACKGROUND for y in range(h2 - 150, h2 - 10) for x in range(x0, x0 + 160)]
a, b = cell(2), cell(164)
check("two cells differ where the bend moved the tube", rc == 0 and sum(1 for p, q in zip(a, b) if p != q) > 1000, err)

# --diff against a copy whose bulge target moves one vertex 0.3 further: only the cell that
# plays bulge lights up (yellow, the hot end of the color map), around that one vertex.
rc, out, err = run("export", path("ex.morph"), "-o", path("ex.gltf"))
doc = json.load(open(path("ex.gltf")))
prim = doc["meshes"][0]["primitives"][0]
acc = doc["accessors"][prim["targets"][0]["POSITION"]]
view = doc["bufferViews"][acc["bufferView"]]
uri = doc["buffers"][0]["uri"]
head, b64 = uri.split(",", 1)
buf = bytearray(base64.b64decode(b64))
at = view["byteOffset"] + acc.get("byteOffset", 0) + 12 * 400   # vertex 400, x
x, = struct.unpack_from("<f", buf, at)
struct.pack_into("<f", buf, at, x + 0.3)
acc["max"][0] = max(acc["max"][0], x + 0.3)
doc["buffers"][0]["uri"] = head + "," + base64.b64encode(bytes(buf)).decode()
json.dump(doc, open(path("moved.gltf"), "w"))
rc, out, err = run("import", path("moved.gltf"), "--channels", path("ex.channels.json"), "-o", path("moved.morph"),
                   "--precision", "float")
check("import the moved copy", rc == 0, err)
rc, out, err = run("render", path("ex.morph"), "--diff", path("moved.morph"), "--weights", "bulge=0;bulge=1",
                   "--view", "front", "--size", "200x200", "--columns", "2", "-o", path("diff.png"))
check("render --diff", rc == 0, err)
w3, h3, px3 = read_png(path("diff.png"))
hot = lambda p: p[0] > 180 and p[1] > 170 and p[2] < 120
hot_cells = [sum(1 for y in range(h3) for x in range(x0, x0 + 200) if hot(px3[y][x])) for x0 in (2, 204)]
# The legend's bar has hot pixels too: count only above it (the cells end where the legend starts).
top = next(y for y in range(h3) if px3[y][1] == (18, 19, 22) and y > 40)
hot_cells = [sum(1 for y in range(top) for x in range(x0, x0 + 200) if hot(px3[y][x])) for x0 in (2, 204)]
check("only the cell that plays the moved target is hot", hot_cells[0] == 0 and hot_cells[1] > 10, hot_cells)

# --normal-error: the angle to the surface's normals. The clip combines bend and bulge, where
# nlerp leaves the surface by degrees; surface normals are the reference, so they have none. The
# hot cells are the ones the summary's largest angle comes from.
errors = {}
for mode in ("nlerp", "surface"):
    rc, out, err = run("render", path("ex.morph"), "--normal-error", "--normals", mode, "--frames", "6", "--columns", "6",
                       "--size", "120x120", "-o", path("normals_%s.png" % mode))
    m = re.search(r"largest normal error ([0-9.e+-]+) degrees", out)
    check("render --normal-error --normals %s" % mode, rc == 0 and m is not None, (rc, out, err))
    errors[mode] = float(m.group(1)) if m else -1
check("nlerp is degrees off the surface where the shapes combine, surface normals are not",
      errors["nlerp"] > 5 and 0 <= errors["surface"] < 1e-3, errors)
if errors["nlerp"] > 0:
    w4, h4, px4 = read_png(path("normals_nlerp.png"))
    top4 = next(y for y in range(h4) if px4[y][1] == (18, 19, 22) and y > 40)
    hot4 = [sum(1 for y in range(top4) for x in range(x0, x0 + 120) if hot(px4[y][x])) for x0 in range(2, 6 * 122, 122)]
    check("the rest pose is cold and a combined pose is hot", hot4[0] == 0 and max(hot4) > 10, hot4)

# Bad values: a clear message, exit 2 (usage) or 1 (failure), and no picture.
for args, code, words in [
    (["--size", "0x0"], 2, "a cell must be 32 to 4096 pixels a side"),
    (["--size", "99999x99999"], 2, "a cell must be"),
    (["--size", "512"], 2, "write WIDTHxHEIGHT"),
    (["--times", "0,nan"], 2, '"nan" is not a number of seconds'),
    (["--frames", "4000"], 1, "need more than 16384 pixels a side"),
    (["--diff", path("missing.morph")], 1, "missing.morph"),
    (["--scale-max", "1"], 2, "--scale-max needs --diff or --normal-error"),
    (["--diff", path("ex.morph"), "--normal-error"], 2, "pick one"),
]:
    rc, out, err = run("render", path("ex.morph"), "-o", path("bad.png"), *args)
    check("render %s refused" % " ".join(args), rc == code and words in err and not os.path.exists(path("bad.png")),
          (rc, err))
rc, out, err = run("render", path("ex.morph"), "-o", path("sheet.txt"))
check("a name not ending in .png is refused", rc == 2 and "must end in .png" in err, err)
rc, out, err = run("render", path("ex.morph"), "-o", path("ex.morph"))
check("the input is not overwritten", rc == 2 and "refusing to overwrite the input" in err, err)

# bake --plot: one panel per channel, the error curve drawn, the tolerance line where the
# recipe is adaptive, one mark per in-between; written with the blob or not at all.
recipes = os.path.join(os.environ.get("MORPHKIT_SOURCE_ROOT", os.path.join(os.path.dirname(__file__), "..", "..")),
                       "samples", "recipes")
rc, out, err = run("bake", path("ex.morph"), "--recipe", os.path.join(recipes, "barr.json"), "-o", path("baked.morph"),
                   "--plot", path("plot.png"), "--quiet")
check("bake --plot writes the blob and the plot", rc == 0 and os.path.isfile(path("baked.morph")), err)
channels = [l for l in out.splitlines() if l.startswith("channel ")]
targets = [int(re.search(r": (\d+) targets?,", l).group(1)) for l in channels]
pw, ph, pp = read_png(path("plot.png"))
check("one 720x200 panel per channel", (pw, ph) == (720, 200 * len(channels)) and len(channels) == 3, (pw, ph, channels))
CURVE, LIMIT, MARK = (250, 220, 90), (235, 110, 80), (120, 160, 230)
def panel_columns(i, color):
    return sorted({x for y in range(200 * i + 22, 200 * i + 180) for x in range(64, 711) if pp[y][x] == color})
def runs(cols):
    return sum(1 for k, x in enumerate(cols) if k == 0 or x != cols[k - 1] + 1)
for i, t in enumerate(targets):
    check("panel %d: the curve spans the weights" % i, len(panel_columns(i, CURVE)) > 500)
    check("panel %d: one mark per target (%d)" % (i, t), runs(panel_columns(i, MARK)) == t, runs(panel_columns(i, MARK)))
adaptive = [i for i, l in enumerate(channels) if "bend" in l]
check("the adaptive channel shows its tolerance line", adaptive and len(panel_columns(adaptive[0], LIMIT)) > 200)
rc, out, err = run("bake", path("ex.morph"), "--recipe", os.path.join(recipes, "barr.json"), "-o", path("baked2.morph"),
                   "--plot", path("plot.jpg"))
check("--plot must name a .png", rc == 2 and not os.path.exists(path("baked2.morph")), err)
os.mkdir(path("plot_dir.png"))
rc, out, err = run("bake", path("ex.morph"), "--recipe", os.path.join(recipes, "barr.json"), "-o", path("baked3.morph"),
                   "--plot", path("plot_dir.png"))
check("an impossible --plot leaves no blob behind", rc != 0 and not os.path.exists(path("baked3.morph")), err)

# bake --plot with shell channels: one chart of every shell channel's volume ratio above the
# error panels, each curve in its color over its simulated time, the legend naming them.
subprocess.run([make_example, "--ball", path("ball.morph")], check=True, capture_output=True)
rc, out, err = run("bake", path("ball.morph"), "--recipe", os.path.join(recipes, "shell.json"), "-o",
                   path("shell.morph"), "--plot", path("shell.png"), "--quiet")
check("bake --plot on shell channels", rc == 0 and os.path.isfile(path("shell.png")), err)
if rc == 0:
    pw, ph, pp = read_png(path("shell.png"))
    check("a 720x260 volume chart above one panel per channel", (pw, ph) == (720, 260 + 2 * 200), (pw, ph))
    FIRST, SECOND = (250, 220, 90), (110, 190, 250)
    def chart_columns(color):   # the plot area, left of the legend
        return sorted({x for y in range(22, 228) for x in range(64, 600) if pp[y][x] == color})
    first, second = chart_columns(FIRST), chart_columns(SECOND)
    # "deflate" runs 100 frames, "dent" 60 (dt 0.01 both): x = 64 + 646 * frame / 100.
    check("the 100-frame curve reaches the legend's edge, the 60-frame one ends at 0.6 s",
          first and first[-1] >= 599 and second and abs(second[-1] - (64 + 646 * 0.6)) <= 3,
          (first[-1:] , second[-1:]))
    top_y = min(y for y in range(22, 228) if pp[y][66] in (FIRST, SECOND))
    end_y = max(y for y in range(22, 228) for x in range(second[-1] - 3, second[-1] + 1) if pp[y][x] == SECOND)
    check("volumes start at V/V0 = 1 (the top) and fall", top_y <= 24 and end_y > 100, (top_y, end_y))
    legend = sum(1 for y in range(22, 80) for x in range(600, 711) if pp[y][x] in (FIRST, SECOND))
    check("the legend names both channels in their colors", legend > 60, legend)

# conform --report: golden frames of the example, plus a case whose reference is the moved copy
# (so its frame fails); the page lists every frame, links only pictures that exist, shows the
# failing frame first, and opens in headless Chromium without errors.
import re, shutil
rc, out, err = run("frames", path("ex.morph"), "--weights", "bulge=1;bend=0.5", "-o", path("golden"))
rc, out, err = run("frames", path("moved.morph"), "--weights", "bulge=1", "-o", path("golden_moved"))
manifest = json.load(open(path("golden/manifest.json")))
bad = json.loads(json.dumps(manifest["cases"][0]))
bad["name"] = "moved-reference"
bad["reference"]["kind"] = "morphkit-json"
bad["frames"] = [dict(bad["frames"][0], file="../golden_moved/frame_000.json")]
manifest["cases"].append(bad)
json.dump(manifest, open(path("golden/with_failure.json"), "w"))
rc, out, err = run("conform", path("golden/with_failure.json"), "--report", path("report"))
check("conform --report fails with the failing frame but writes the report",
      rc == 1 and os.path.isfile(path("report/index.html")), (rc, out, err))
html = open(path("report/index.html")).read() if os.path.isfile(path("report/index.html")) else ""
rows = re.findall(r"<tr class=\"(ok|fail)\">", html)
check("the table lists every frame (2 cases x 2 frames + 1)", len(rows) == 5 and rows.count("fail") == 1, rows)
images = re.findall(r'<img src="([^"]+)"', html)
check("one picture per frame, each one exists", len(images) == 5 and all(os.path.isfile(path("report/" + i)) for i in images),
      images)
check("nothing in the folder that the page does not link",
      sorted(os.listdir(path("report"))) == sorted(images + ["index.html"]), os.listdir(path("report")))
check("the failing frame's picture comes first", images and images[0] == "frame_0004.png", images[:2])
check("the failing row says where", re.search(r'class="fail">.*?<td>tube v400</td>', html) is not None)
if images:
    w4, h4, px4 = read_png(path("report/" + images[0]))
    check("frame pictures are modest", w4 <= 800 and h4 <= 400, (w4, h4))
chromium = shutil.which("chromium") or shutil.which("chromium-browser")
if not chromium:
    skip("chromium", "not installed (Debian package chromium)")
else:
    p = subprocess.run([chromium, "--headless", "--no-sandbox", "--disable-gpu", "--enable-logging=stderr", "--v=0",
                        "--dump-dom", "file://" + path("report/index.html")], capture_output=True, text=True, timeout=120)
    errors = [l for l in p.stderr.splitlines() if "ERR_FILE_NOT_FOUND" in l or "Uncaught" in l or ":CONSOLE" in l]
    check("headless Chromium opens the report (table and 5 images in its DOM, no console errors)",
          p.returncode == 0 and "<table>" in p.stdout and p.stdout.count("<img") == 5 and not errors,
          (p.returncode, errors[:3], p.stderr[-400:]))

finish()
