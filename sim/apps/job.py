"""A simulation in a child process that a signal stops at once: how the ``eyestereo sim`` commands run benches.

A command that runs a bench in its own process cannot be stopped while the simulator runs: cocotb's
runner waits for GHDL (or the Verilator model) in a plain ``subprocess.run``, a Ctrl-C in a terminal
reaches the simulator and the Python inside it at the same time (that once left a run hung), and a
SIGTERM sent to the command alone leaves the simulator running. So the commands hand the bench to
:func:`run_job`:

* the bench runs in a child Python (``python -m eyestereo.sim.apps.job SPEC``) in a session of its own: a
  terminal's Ctrl-C reaches only the command, which then decides;
* the command's main thread waits in short steps (polling the bench's progress file between them), so
  the signal handler of :mod:`eyestereo.tools.cli.common` (SIGINT, SIGTERM, SIGHUP raise
  :class:`~eyestereo.tools.io.Interrupted`) runs at once; :func:`run_job` then ends the child's whole
  process group (SIGTERM, SIGKILL after :data:`GRACE` seconds) and re-raises: the run folder is removed
  by :func:`run_folder`, the outputs by :class:`~eyestereo.tools.io.Outputs`, and the command says
  "interrupted; nothing was written";
* builds go to a folder of the user's (:func:`run_folder`: ``--build-dir``, ``$EYESTEREO_BUILD_DIR``, else
  the system's temporary folder), never into the installed package, one fresh folder per run, so two
  runs at once never share a build.

A failed simulation raises :class:`JobFailed` (a ValueError: one line, exit status 1) naming the log,
and :func:`run_folder` keeps that run's folder so the log it names exists.
"""

from __future__ import annotations

import contextlib
import importlib
import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

__all__ = ["GRACE", "JobFailed", "check_build_dir", "default_build_dir", "file_progress", "run_folder", "run_job",
           "run_jobs"]

#: Seconds between SIGTERM and SIGKILL when a job is stopped.
GRACE = 1.0
#: Seconds between two looks at the child (and calls of the progress callback).
STEP = 0.2
BUILD_ENV = "EYESTEREO_BUILD_DIR"


class JobFailed(ValueError):
    """The simulation failed; ``log`` is the file that says why (kept by :func:`run_folder`)."""

    def __init__(self, message: str, log: Path | None = None) -> None:
        super().__init__(message)
        self.log = log


def default_build_dir() -> Path:
    """``$EYESTEREO_BUILD_DIR``, else the system's temporary folder (``$TMPDIR``, /tmp)."""
    env = os.environ.get(BUILD_ENV)
    return Path(env) if env else Path(tempfile.gettempdir())


def check_build_dir(build_dir: str | os.PathLike[str] | None) -> Path:
    """The build folder to use: ``build_dir`` or :func:`default_build_dir`; ValueError (one line) when it
    is not a folder that can be created and written (checked before any work)."""
    root = Path(build_dir) if build_dir else default_build_dir()
    what = "--build-dir" if build_dir else (f"${BUILD_ENV}" if os.environ.get(BUILD_ENV) else "the temporary folder")
    if root.exists() and not root.is_dir():
        raise ValueError(f"{what} {root} is not a folder")
    if not root.exists() and not root.parent.is_dir():
        raise ValueError(f"{what} {root}: folder {root.parent} does not exist")
    probe = root if root.exists() else root.parent
    if not os.access(probe, os.W_OK | os.X_OK):
        raise ValueError(f"{what} {root} is not writable")
    return root


@contextlib.contextmanager
def run_folder(command: str, build_dir: str | os.PathLike[str] | None = None) -> Iterator[Path]:
    """A fresh folder for one run (``<build dir>/eyestereo-<command>-XXXXXXXX``), removed when the block
    ends, unless a :class:`JobFailed` ends it (then kept, so the log named in the message exists)."""
    root = check_build_dir(build_dir)
    root.mkdir(exist_ok=True)
    folder = Path(tempfile.mkdtemp(prefix=f"eyestereo-{command}-", dir=root))
    keep = False
    try:
        yield folder
    except JobFailed:
        keep = True
        raise
    finally:
        if not keep:
            shutil.rmtree(folder, ignore_errors=True)


def _jsonable(value: Any) -> Any:
    if isinstance(value, Path):
        return str(value)
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_jsonable(v) for v in value]
    return value


def _stop(proc: subprocess.Popen) -> None:
    """End the child's process group: SIGTERM, then SIGKILL after :data:`GRACE` seconds."""
    for sig, wait in ((signal.SIGTERM, GRACE), (signal.SIGKILL, 5.0)):
        with contextlib.suppress(ProcessLookupError, PermissionError):
            os.killpg(proc.pid, sig)
        try:
            proc.wait(wait)
            break
        except subprocess.TimeoutExpired:
            continue
    # the group may outlive its leader for a moment (the simulator exiting): make sure it is gone
    with contextlib.suppress(ProcessLookupError, PermissionError):
        os.killpg(proc.pid, signal.SIGKILL)


class _Child:
    """One child process running a target (see :func:`run_jobs`)."""

    def __init__(self, target: str, kwargs: dict, folder: Path, what: str) -> None:
        self.folder, self.what = Path(folder), what
        self.result, self.log = self.folder / "job.result.json", self.folder / "job.log"
        spec = self.folder / "job.json"
        spec.write_text(json.dumps(dict(target=target, kwargs=_jsonable(kwargs), result=str(self.result))))
        env = dict(os.environ, PYTHONUNBUFFERED="1")
        with open(self.log, "wb") as fh:
            self.proc = subprocess.Popen([sys.executable, "-m", "eyestereo.sim.apps.job", str(spec)],
                                         stdin=subprocess.DEVNULL, stdout=fh, stderr=subprocess.STDOUT,
                                         start_new_session=True, env=env, cwd=str(self.folder))

    def running(self) -> bool:
        return self.proc.poll() is None

    def stop(self) -> None:
        _stop(self.proc)

    def value(self) -> Any:
        self.stop()  # the simulator's own children, should any be left
        try:
            out = json.loads(self.result.read_text())
        except (OSError, ValueError):
            raise JobFailed(f"{self.what} ended without a result (status {self.proc.returncode}); log: {self.log}",
                            self.log) from None
        if not out.get("ok"):
            first = (str(out.get("message") or "").strip().splitlines() or [""])[0][:300]
            logs = [self.log] + [Path(p) for p in out.get("logs", []) if Path(p).exists()]
            raise JobFailed(f"{self.what} failed ({out.get('type')}: {first}); log: {logs[-1]}", logs[-1])
        return out.get("value")


def run_jobs(jobs: list[tuple[str, dict, Path]], *, at_once: int = 1, progress: Callable[[], None] | None = None,
             what: str = "the simulation") -> list[Any]:
    """Run several jobs (``(target, kwargs, folder)``, each as in :func:`run_job`, each its own folder),
    ``at_once`` at a time; their results in order. The first failure stops the others and raises."""
    pending = list(enumerate(jobs))
    running: list[tuple[int, _Child]] = []
    results: dict[int, Any] = {}
    try:
        while pending or running:
            while pending and len(running) < max(1, at_once):
                i, (target, kwargs, folder) = pending.pop(0)
                running.append((i, _Child(target, kwargs, folder, what)))
            time.sleep(STEP)
            if progress is not None:
                progress()
            for item in [r for r in running if not r[1].running()]:
                running.remove(item)
                results[item[0]] = item[1].value()
    except BaseException:
        for _, child in running:
            child.stop()
        raise
    return [results[i] for i in range(len(jobs))]


def run_job(target: str, kwargs: dict, folder: Path, *, progress: Callable[[], None] | None = None,
            what: str = "the simulation") -> Any:
    """Call ``target`` (``"module:function"``) with ``kwargs`` (JSON-able; paths become strings) in a child
    process whose files live in ``folder``; returns its JSON-able result.

    ``progress`` is called every :data:`STEP` seconds while the child runs. Any exception in the waiting
    thread (a signal's :class:`~eyestereo.tools.io.Interrupted`, a KeyboardInterrupt) stops the child's
    process group before it propagates. The child's exception comes back as :class:`JobFailed`
    (``what`` failed, its first line, and the log).
    """
    return run_jobs([(target, kwargs, folder)], progress=progress, what=what)[0]


def main(argv: list[str] | None = None) -> int:
    """The child: run the spec's target, write its result (or its exception) as JSON."""
    argv = sys.argv[1:] if argv is None else argv
    spec = json.loads(Path(argv[0]).read_text())
    result = Path(spec["result"])
    try:
        module, _, name = spec["target"].partition(":")
        value = getattr(importlib.import_module(module), name)(**spec["kwargs"])
        out = dict(ok=True, value=_jsonable(value))
    except BaseException as e:  # noqa: BLE001 - every failure goes back to the parent as data
        import traceback

        traceback.print_exc()
        logs = [str(p) for p in Path(result.parent).rglob("*.log") if p.name != "job.log"]
        logs.sort(key=lambda p: os.stat(p).st_mtime)
        out = dict(ok=False, type=type(e).__name__, message=str(e), logs=logs)
    tmp = result.with_name(result.name + ".part")
    tmp.write_text(json.dumps(out))
    os.replace(tmp, result)
    return 0 if out["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())


def file_progress(path: Path, bar: Any, total: int) -> Callable[[], None]:
    """A progress callback for :func:`run_job`: moves ``bar`` (a :func:`~eyestereo.tools.progress.progress_bar`)
    to the first number in ``path``, a file the bench rewrites now and then (missing or half-written
    files are skipped)."""
    def poll() -> None:
        try:
            done = int(Path(path).read_text().split()[0])
        except (OSError, ValueError, IndexError):
            return
        bar.update(max(0, min(done, total) - bar.n))

    return poll
