#!/bin/bash
# tests/mutation/run.sh: mutation testing of the code that carries
# aafarm's promises (issue 27, item 7). Not run by ctest or CI: a full run
# takes about 1-3 minutes per mutant on two cores.
#
#   tests/mutation/run.sh [-k] [ID ...]
#
# Copies the working tree (without build folders) to a scratch folder
# ($MUTATION_DIR, default /tmp/aafarm-mutation), configures it once
# (RelWithDebInfo, asserts on), and for each mutant of
# tests/mutation/mutants.txt (or only the IDs given): applies its edits,
# builds, runs its tests (`ctest -R REGEX`, each bounded by ctest's
# timeout), restores the files. A mutant is "caught" when a test fails or
# the build breaks, "missed" when every test passes, "stale" when its text
# is no longer on its line. Prints a table (markdown) at the end; exit 1 if
# any mutant was missed or stale. -k keeps the scratch folder (reused by the
# next run with -k: incremental builds).
set -u
here=$(cd "$(dirname "$0")" && pwd)
src=$(cd "$here/../.." && pwd)
keep=0
if [ "${1:-}" = "-k" ]; then keep=1; shift; fi
scratch=${MUTATION_DIR:-/tmp/aafarm-mutation}
mkdir -p "$scratch"
# a fresh copy (mtimes kept: a kept build stays incremental)
rm -rf "$scratch/src" && mkdir -p "$scratch/src" || exit 2
tar -C "$src" --exclude='./build*' --exclude='./.git' -cf - . | tar -C "$scratch/src" -xf - || exit 2
if [ ! -f "$scratch/build/CMakeCache.txt" ]; then
    cmake -S "$scratch/src" -B "$scratch/build" -DCMAKE_BUILD_TYPE=RelWithDebInfo \
        -DAAFARM_ASSERTS=ON >"$scratch/configure.log" 2>&1 || { echo "configure failed"; exit 2; }
fi
echo "building the unmutated tree ..."
nice cmake --build "$scratch/build" -j2 >"$scratch/build.log" 2>&1 || { echo "the unmutated build fails"; exit 2; }
python3 - "$here/mutants.txt" "$scratch" "$@" <<'PY'
import os, subprocess, sys, time
mfile, scratch, only = sys.argv[1], sys.argv[2], set(sys.argv[3:])
src, build = os.path.join(scratch, "src"), os.path.join(scratch, "build")
mutants, cur = [], None
for line in open(mfile):
    line = line.rstrip("\n")
    if not line.strip() or line.startswith("#"):
        continue
    if line.startswith("@ "):
        cur = {"id": line[2:].strip(), "edits": []}
        mutants.append(cur)
        continue
    key, _, val = line.partition(": ")
    if key == "edit":
        f, _, n = val.rpartition(":")
        cur["edits"].append({"file": f, "line": int(n)})
    elif key in ("old", "new"):
        cur["edits"][-1][key] = val
    else:
        cur[key] = val
rows = []
for m in mutants:
    if only and m["id"] not in only:
        continue
    saved, verdict, detail = {}, None, ""
    for e in m["edits"]:
        path = os.path.join(src, e["file"])
        if path not in saved:
            saved[path] = open(path).read()
        lines = open(path).read().split("\n")
        i = e["line"] - 1
        if i >= len(lines) or e["old"] not in lines[i]:
            verdict, detail = "stale", "%s:%d no longer has the text" % (e["file"], e["line"])
            break
        lines[i] = lines[i].replace(e["old"], e["new"], 1)
        open(path, "w").write("\n".join(lines))
    t0 = time.time()
    if not verdict:
        b = subprocess.run(["nice", "cmake", "--build", build, "-j2"], capture_output=True, text=True)
        if b.returncode != 0:
            verdict, detail = "caught", "the build breaks"
        else:
            r = subprocess.run(["nice", "ctest", "-R", m["tests"], "--output-on-failure"], cwd=build,
                               capture_output=True, text=True)
            # ctest's summary lines: "  12 - test_name (Failed)"
            failed = [l.split(" - ", 1)[1].split()[0] for l in r.stdout.splitlines()
                      if " - " in l and ("(Failed)" in l or "(Timeout)" in l or "Exception" in l)]
            ran = "No tests were found" not in r.stdout + r.stderr
            if not ran:
                verdict, detail = "stale", "no test matches " + m["tests"]
            elif r.returncode != 0:
                verdict, detail = "caught", "failed: " + ", ".join(sorted(set(failed))) if failed else "caught"
            else:
                verdict, detail = "missed", "all of " + m["tests"] + " pass"
    for path, text in saved.items():
        open(path, "w").write(text)
    secs = time.time() - t0
    rows.append((m["id"], m.get("what", ""), verdict, detail, secs))
    print("%-26s %-7s %5.0f s  %s" % (m["id"], verdict, secs, detail), flush=True)
# the tree as it was, built again (the next run starts from it)
subprocess.run(["nice", "cmake", "--build", build, "-j2"], capture_output=True)
print()
print("| mutant | what | verdict | tests |")
print("|---|---|---|---|")
for r in rows:
    print("| %s | %s | %s | %s |" % (r[0], r[1], r[2], r[3]))
caught = sum(1 for r in rows if r[2] == "caught")
print("\n%d of %d caught" % (caught, len(rows)))
sys.exit(0 if caught == len(rows) else 1)
PY
rc=$?
[ "$keep" = 1 ] || rm -rf "$scratch"
exit $rc
