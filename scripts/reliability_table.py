#!/usr/bin/env python3
"""Runs the hostile-input cases of docs/RELIABILITY.md against a build and
prints the table there: each case's command, exit status and the first line
of what crumple said (stderr and stdout together; a note line for the cases
that succeed with a notice).

    python3 scripts/reliability_table.py [BUILD_DIR]   # default: build

Every case is also a test in the default suite
(tests/pipeline/test_reliability.cpp and the files the table names); this
script only shows them. Takes about a minute. The two cost-guard cases of
the page take minutes each and are measured there, not here.
"""
import os
import re
import shutil
import signal
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
BUILD = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build"))
CRUMPLE = os.path.join(BUILD, "crumple")
WORK = tempfile.mkdtemp(prefix="crumple-reliability-")
ROWS = []


def run(args, shell=False):
    p = subprocess.run(args, shell=shell, capture_output=True, text=True, cwd=WORK)
    lines = [l for l in (p.stderr + p.stdout).splitlines()
             if l.strip() and not l.startswith(("PROGRESS", "SUMMARY", "warning:"))]
    first = next((l for l in lines if "error" in l or "failure" in l or "note:" in l),
                 lines[0] if lines else "")
    return p.returncode, first.strip()


def case(name, shown, args, shell=False):
    code, first = run(args, shell)
    ROWS.append((name, shown, code, first.replace(WORK + "/", "").replace("|", "\\|")))


def scene_copy(name, edit=None):
    d = os.path.join(WORK, name)
    shutil.copytree(os.path.join(ROOT, "samples", "drape"), d)
    if edit:
        p = os.path.join(d, "scene.toml")
        with open(p) as f:
            text = f.read()
        for old, new in edit:
            text, n = re.subn(old, new, text, count=1, flags=re.M)
            assert n == 1, old
        with open(p, "w") as f:
            f.write(text)
    return d


def chunks(data):
    off = 8
    while off + 20 <= len(data):
        tag = data[off:off + 4]
        length = struct.unpack_from("<Q", data, off + 8)[0]
        yield off, tag, length
        off += 16 + length + 4


def patched(data, chunk, at, fmt, value):
    b = bytearray(data)
    struct.pack_into(fmt, b, chunk + 16 + at, value)
    length = struct.unpack_from("<Q", b, chunk + 8)[0]
    end = chunk + 16 + length
    struct.pack_into("<I", b, end, zlib.crc32(bytes(b[chunk:end])) & 0xFFFFFFFF)
    return bytes(b)


def write(name, data):
    p = os.path.join(WORK, name)
    with open(p, "wb") as f:
        f.write(data)
    return name


def main():
    sim = scene_copy("drape")
    with open(os.path.join(sim, "scene.toml"), "a") as f:
        f.write("\n[sound]\n")
    subprocess.run([CRUMPLE, "simulate", "drape", "--frames", "0-5", "--out", "out"], cwd=WORK,
                   capture_output=True, check=True)
    cache = open(os.path.join(WORK, "out", "cache.pcache"), "rb").read()
    head = next(c for c in chunks(cache) if c[1] == b"HEAD")[0]
    frames = [c for c in chunks(cache) if c[1] == b"FRAM"]

    # 1. CRC-valid caches with hostile indices (tests/fuzz/regressions/cache_tools).
    reg = os.path.join(ROOT, "tests", "fuzz", "regressions", "cache_tools")
    for f, cmd in [("triangle-index-minus-5.pcache", "inspect"),
                   ("triangle-index-999999.pcache", "inspect"),
                   ("triangle-index-equal-to-vertex-count.pcache", "inspect --json"),
                   ("handle-vertex-1e7.pcache", "render --debug-structure --frames 0-0")]:
        shutil.copy(os.path.join(reg, f), os.path.join(WORK, f))
        case("1. CRC-valid cache, " + f.replace(".pcache", "").replace("-", " "),
             f"crumple {cmd} {f}", [CRUMPLE] + cmd.split() + [f])
    # 5. A cache with NaN, 0 or negative fps; a NaN position.
    for label, fps in [("NaN", float("nan")), ("0", 0.0), ("negative", -24.0)]:
        name = write(f"fps-{label}.pcache", patched(cache, head, 4, "<d", fps))
        for cmd in (["sound"], ["export", "--format", "usda"], ["export", "--format", "gltf"]):
            case(f"5. cache with {label} fps", "crumple " + " ".join(cmd) + f" {name}",
                 [CRUMPLE] + cmd + [name, "--out", os.path.join(WORK, "o-" + label)])
    frame0 = frames[0][0]
    payload = cache[frame0 + 16:frame0 + 16 + frames[0][2]]
    ntri = struct.unpack_from("<I", payload, 13)[0]
    pos = 17 + 12 * ntri
    pos += 4 + 4 * struct.unpack_from("<I", payload, pos)[0]
    pos += 4 + struct.unpack_from("<I", payload, pos)[0]
    pos += 4 + 16 * struct.unpack_from("<I", payload, pos)[0]
    name = write("nan-position.pcache", patched(cache, frame0, pos + 4 + 8, "<d", float("nan")))
    case("5. cache with a NaN position", f"crumple render {name}", [CRUMPLE, "render", name])
    # 6. A footerless cache: three complete frames of six.
    cut = write("cut.pcache", cache[:frames[3][0]])
    for cmd in (["render"], ["sound"], ["export", "--format", "obj"]):
        case("6. cache without its footer", "crumple " + " ".join(cmd) + " cut.pcache",
             [CRUMPLE] + cmd + [cut, "--out", os.path.join(WORK, "cut-" + cmd[0])])
    # 2. Two writers into one folder.
    scene_copy("long")
    first = subprocess.Popen([CRUMPLE, "simulate", "long", "--out", "busy"], cwd=WORK,
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    time.sleep(1.5)
    case("2. a second writer into a folder being written", "crumple simulate drape --out busy",
         [CRUMPLE, "simulate", "drape", "--out", "busy"])
    first.send_signal(signal.SIGKILL)
    first.wait()
    # 3. --resume after the animation file changed.
    subprocess.run([CRUMPLE, "simulate", "drape", "--frames", "0-4", "--checkpoint-every", "2",
                    "--out", "ckpt"], cwd=WORK, capture_output=True, check=True)
    anim = os.path.join(sim, "drape.gltf")
    with open(anim, "a") as f:
        f.write(" ")
    case("3. --resume with the animation file changed",
         "crumple simulate drape --frames 0-4 --resume --out ckpt",
         [CRUMPLE, "simulate", "drape", "--frames", "0-4", "--resume", "--out", "ckpt"])
    # 5. Sizes at parse time.
    for label, edit in [("width = 1e15 cm", [(r"^width = .*", "width = 1e15")]),
                        ("width = 1e30 cm", [(r"^width = .*", "width = 1e30")]),
                        ("width = 1e9 cm", [(r"^width = .*", "width = 1e9")]),
                        ("width = 1e6 cm", [(r"^width = .*", "width = 1e6")]),
                        ("max_edge = 0.01 cm", [(r"^max_edge = .*", "max_edge = 0.01")]),
                        ("resolution = [16384, 16384]",
                         [(r"^resolution = .*", "resolution = [16384, 16384]")]),
                        ("name = \"../../escape\"", [(r"^name = .*", 'name = "../../escape"')]),
                        ("animation = \"drape.txt\"",
                         [(r"^animation = .*", 'animation = "drape.txt"')]),
                        ("both handles at pattern [0, 29.7]",
                         [(r"^pattern = \[21.0, 29.7\]", "pattern = [0.0, 29.7]")])]:
        d = scene_copy("s-" + re.sub(r"\W+", "-", label), edit)
        case("5/8. scene with " + label, "crumple simulate SCENE",
             [CRUMPLE, "simulate", os.path.basename(d), "--frames", "0-0", "--out",
              os.path.join(WORK, "o")])
    # 5 and 8. The command line.
    for label, args in [("--seed -1", ["simulate", "drape", "--seed", "-1"]),
                        ("--seed of 23 digits",
                         ["simulate", "drape", "--seed", "12345678901234567890123"]),
                        ("compare --tolerance nan",
                         ["compare", "a.png", "b.png", "--tolerance", "nan"]),
                        ("sound --gain-db 1e308",
                         ["sound", "out/cache.pcache", "--gain-db", "1e308"]),
                        ("an unknown command", ["frobnicate"])]:
        case("5/8. " + label, "crumple " + " ".join(args), [CRUMPLE] + args)
    case("8. sound --out naming a folder", "crumple sound out/cache.pcache --out wavs/",
         [CRUMPLE, "sound", "out/cache.pcache", "--out", "wavs/"])
    # 8. Keys that go back in time (the second key of HandleL before the first).
    d = scene_copy("keys")
    subprocess.run([sys.executable, "-c", open(os.path.join(ROOT, "samples", "drape",
                   "make_drape_gltf.py")).read().replace(
        "TIMES = [0.0, 0.5,", "TIMES = [0.5, 0.0,").replace(
        'os.path.dirname(os.path.abspath(__file__))', repr(d))], check=True)
    case("8. decreasing key times", "crumple simulate keys",
         [CRUMPLE, "simulate", "keys", "--frames", "0-0", "--out", os.path.join(WORK, "o")])

    print("| case | command | exit | first line |")
    print("| --- | --- | ---: | --- |")
    for name, shown, code, first in ROWS:
        print(f"| {name} | `{shown}` | {code} | {first} |")
    shutil.rmtree(WORK, ignore_errors=True)


if __name__ == "__main__":
    main()
