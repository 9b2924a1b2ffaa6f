"""What the command-line test scripts share: where the sources and the corpus are, a scratch
folder, a way to run the command, and check/skip counters that end in the suite's
"N passed, N failed, N skipped" line."""
import os, subprocess, sys, tempfile

root = os.environ.get("MORPHKIT_SOURCE_ROOT", os.path.join(os.path.dirname(__file__), "..", ".."))
corpus = os.environ.get("MORPHKIT_CORPUS", os.path.join(root, "..", "shared", "corpus"))
have_corpus = os.path.isfile(os.path.join(corpus, "cases.json"))
counts = {"passed": 0, "failed": 0, "skipped": 0}


def scratch(prefix):
    return tempfile.mkdtemp(prefix=prefix)


def runner(program, timeout=300):
    """A function run(*args, stdin=None) -> (exit status, stdout, stderr) of `program args...`
    (text, captured)."""
    def run(*args, stdin=None):
        p = subprocess.run([program] + [str(a) for a in args], capture_output=True, text=True, stdin=stdin,
                           timeout=timeout)
        return p.returncode, p.stdout, p.stderr
    return run


def read_bytes(path):
    with open(path, "rb") as f:
        return f.read()


def check(name, cond, detail=""):
    if cond:
        counts["passed"] += 1
        print("ok   " + name)
    else:
        counts["failed"] += 1
        print("FAIL " + name + ("\n     " + detail.replace("\n", "\n     ")[-1500:] if detail else ""))
    return bool(cond)


def skip(name, why):
    counts["skipped"] += 1
    print("skip " + name + ": " + why)


def finish():
    """Prints the summary line and exits 1 when a check failed."""
    print("%d passed, %d failed, %d skipped" % (counts["passed"], counts["failed"], counts["skipped"]))
    sys.exit(1 if counts["failed"] else 0)
