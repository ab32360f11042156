"""crumple as a background job: its commands run one after another as child
processes; each prints `PROGRESS <percent>` lines on stderr when it is not on
a terminal, which become the job's progress. Exit status 0 is success, 2 bad
input with one line saying what, 1 an internal failure (README.md)."""

import os
import shutil
import subprocess
import threading

import bpy

from .common import CrumpleError

RUNNING, DONE, FAILED, CANCELLED = "RUNNING", "DONE", "FAILED", "CANCELLED"


def find_crumple(context):
    """The crumple binary: the add-on preferences' path, else $CRUMPLE_BIN,
    else `crumple` on PATH; None when none is executable."""
    prefs = context.preferences.addons.get(__package__)
    path = bpy.path.abspath(prefs.preferences.crumple_path) if prefs else ""
    if not path:
        path = os.environ.get("CRUMPLE_BIN", "") or shutil.which("crumple") or ""
    return path if path and os.path.isfile(path) and os.access(path, os.X_OK) else None


def require_crumple(context):
    path = find_crumple(context)
    if path is None:
        prefs = context.preferences.addons.get(__package__)
        where = prefs.preferences.crumple_path if prefs else ""
        raise CrumpleError(
            "crumple not found%s: set its path in the add-on's preferences, "
            "or CRUMPLE_BIN, or put it on PATH"
            % (" at '%s'" % where if where else ""))
    return path


class Step:
    """One command; `weight` is its share of the job's progress bar."""

    def __init__(self, label, argv, weight):
        self.label, self.argv, self.weight = label, argv, weight


class Job:
    """Runs its steps in order. poll() advances it and returns its state;
    progress is 0-100 over all steps; error holds crumple's own message."""

    def __init__(self, steps, log_path):
        self.steps, self.log_path = steps, log_path
        self.index, self.state, self.error = 0, RUNNING, ""
        self._process = self._reader = self._log = None
        self._percent, self._lines = 0.0, []

    @property
    def label(self):
        return self.steps[min(self.index, len(self.steps) - 1)].label

    @property
    def progress(self):
        total = sum(s.weight for s in self.steps)
        done = sum(s.weight for s in self.steps[:self.index])
        if self.index < len(self.steps):
            done += self.steps[self.index].weight * self._percent / 100.0
        return 100.0 * done / total

    def start(self):
        self._log = open(self.log_path, "w", encoding="utf-8")
        self._launch()
        return self

    def _launch(self):
        step = self.steps[self.index]
        self._percent, self._lines = 0.0, []
        self._log.write("$ %s\n" % " ".join(step.argv))
        self._log.flush()
        try:
            self._process = subprocess.Popen(
                step.argv, stdin=subprocess.DEVNULL, stdout=self._log,
                stderr=subprocess.PIPE, text=True, bufsize=1)
        except OSError as e:
            self._finish(FAILED, "cannot run %s: %s" % (step.argv[0], e.strerror or e))
            return
        self._reader = threading.Thread(target=self._read, args=(self._process.stderr,),
                                        daemon=True)
        self._reader.start()

    def _read(self, stream):
        for line in stream:
            line = line.rstrip("\n")
            if line.startswith("PROGRESS "):
                try:
                    self._percent = min(100.0, max(0.0, float(line.split()[1])))
                except (IndexError, ValueError):
                    pass
                continue
            self._lines.append(line)
            self._log.write(line + "\n")

    def poll(self):
        if self.state != RUNNING or self._process.poll() is None:
            return self.state
        self._reader.join()
        status = self._process.returncode
        if status != 0:
            said = [l for l in self._lines if l.strip()]
            what = said[-1].strip() if said else "no message"
            kind = "bad input" if status == 2 else "failed with exit status %d" % status
            self._finish(FAILED, "crumple %s (%s): %s" % (self.label, kind, what))
            return self.state
        self.index += 1
        if self.index == len(self.steps):
            self._finish(DONE)
        else:
            self._launch()
        return self.state

    def cancel(self):
        """Stops the running command (SIGTERM, then SIGKILL after 5 s)."""
        if self.state != RUNNING:
            return
        self._process.terminate()
        try:
            self._process.wait(5)
        except subprocess.TimeoutExpired:
            self._process.kill()
            self._process.wait()
        self._reader.join()
        self._finish(CANCELLED, "cancelled during %s" % self.label)

    def _finish(self, state, error=""):
        self.state, self.error = state, error
        if self._log:
            self._log.close()
            self._log = None


def shot_steps(crumple, folder, out, refine, sound):
    """simulate, export the frames as PLY (mesh, UVs, regions) and OBJ (its
    tear textures and paper colour), and the soundtrack for [sound]."""
    cache = os.path.join(out, "cache.pcache")
    steps = [Step("simulate", [crumple, "simulate", folder, "--out", out], 80)]
    for fmt in ("ply", "obj"):
        steps.append(Step("export " + fmt, [crumple, "export", cache, "--format", fmt,
                                            "--refine", refine,
                                            "--out", os.path.join(out, fmt)], 8))
    if sound:
        steps.append(Step("sound", [crumple, "sound", cache, "--no-spectrogram",
                                    "--out", os.path.join(out, "sound.wav")], 4))
    return steps
