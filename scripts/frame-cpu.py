#!/usr/bin/env python3
"""The CPU seconds of each frame of a crumple run, as the cost guard sees them
(docs/RELIABILITY.md "The cost guard").

    python3 scripts/frame-cpu.py build/crumple simulate samples/tear-fast --out /tmp/tf

Runs the command, reads the process's CPU time (/proc/PID/stat, user +
system, 10 ms ticks) at each PROGRESS line it writes to stderr, and prints
the time between them (the first value includes the set-up), then the
median, the largest and the total. The exit status is the command's.
"""
import os
import subprocess
import sys


def cpu_seconds(pid, ticks):
    fields = open(f"/proc/{pid}/stat").read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / ticks


def main():
    if len(sys.argv) < 2 or sys.argv[1] in ("-h", "--help"):
        print(__doc__.strip())
        return 0 if len(sys.argv) >= 2 else 2
    ticks = os.sysconf("SC_CLK_TCK")
    process = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                               text=True)
    last, frames = 0.0, []
    for line in process.stderr:
        if not line.startswith("PROGRESS"):
            sys.stderr.write(line)
            continue
        try:
            now = cpu_seconds(process.pid, ticks)
        except OSError:
            continue  # the process is gone
        frames.append(now - last)
        last = now
    process.wait()
    print(" ".join(f"{s:.2f}" for s in frames))
    if frames:
        ordered = sorted(frames)
        print(f"frames {len(frames)} median {ordered[len(ordered) // 2]:.2f} "
              f"max {max(frames):.2f} total {sum(frames):.2f}")
    return process.returncode


if __name__ == "__main__":
    sys.exit(main())
