"""Files in and out: all-or-nothing outputs, the modes they get, and images read with integrity checks.

One policy for every file the toolbox and the command line write:

* **Nothing half-written.** Each output is written to a hidden temporary beside its target
  (``.NAME.XXXXXXXX.SUFFIX``, the suffix kept so that writers choosing the format by the name still
  work) and renamed into place only when complete. :class:`Outputs` does this for a whole set of files
  and folders at once: either every target is replaced, or none is (a failed write, an exception, or
  SIGINT/SIGTERM turned into an exception by the command line, removes every temporary and leaves the
  targets as they were).
* **An existing file is replaced** (as a compiler's ``-o`` does); a target that is a folder is refused.
* **An existing folder is replaced as a whole, and only if it is ours**: empty, or holding nothing but
  names the writing command produces (an earlier run's output). A folder holding anything else is
  refused before any work starts, so a typo in ``-o`` cannot delete or mix into somebody's files.
  Missing folders are created (their parent must exist).
* **Modes as a plain ``open`` would give them**: a new file gets ``0666 & ~umask``, a new folder
  ``0777 & ~umask`` (``mkstemp``'s 0600 never survives); a replaced file or folder keeps its mode.

Reading images (:func:`read_image`) rejects what OpenCV would otherwise decode silently into
half-grey pictures: truncated or corrupt PNG (chunk CRCs, the end chunk, the compressed stream) and
JPEG (the decoder's own "corrupt data" and "premature end" reports), naming the file.
:func:`to_grey8` states the one rule for pixel depths (16-bit reduced to its 8 most significant used
bits, floating point refused); :func:`centre_crop` cuts a test image to a frame size.

The measurement scripts fill their section of a page in ``docs/`` with :func:`write_section`.
"""

from __future__ import annotations

import contextlib
import os
import re
import shutil
import signal
import struct
import sys
import tempfile
import threading
import zlib
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import numpy as np

__all__ = [
    "Interrupted",
    "Outputs",
    "atomic_output",
    "atomic_write_bytes",
    "atomic_write_text",
    "centre_crop",
    "check_image_bytes",
    "check_not_inputs",
    "dir_mode",
    "file_mode",
    "read_image",
    "revision",
    "to_grey8",
    "user_text",
    "write_section",
]

TMP_MARK = ".eyestereo-"  # in every temporary name, so a leftover is recognisable

# temporary path -> the user's path; error messages are rewritten with it (see user_text)
_TEMPS: dict[str, str] = {}
_TEMPS_LOCK = threading.Lock()
_TEMPS_KEPT = 512


# Signals


class Interrupted(BaseException):
    """A signal (SIGINT, SIGTERM, SIGHUP) ended the command; ``signum`` says which, ``written`` whether
    an output had already been put in place when it arrived."""

    def __init__(self, signum: int, written: bool = False) -> None:
        super().__init__(signum)
        self.signum = signum
        self.written = written

    @property
    def status(self) -> int:
        return 128 + self.signum


# Signals received and not yet acted on. A signal handler's exception is lost when the signal lands
# in code whose exceptions Python ignores (a weakref or import-lock callback, a __del__): the run
# would then go on and commit its outputs. Every commit therefore looks here first.
_PENDING: list[int] = []
_COMMITS = [0]  # outputs put in place by this process (so a late signal is reported truthfully)


def interrupt(signum: int, frame: Any = None) -> None:
    """Signal handler: remember ``signum`` and raise :class:`Interrupted` (see :func:`check_interrupt`)."""
    _PENDING.append(signum)
    raise Interrupted(signum, written=_COMMITS[0] > 0)


def check_interrupt() -> None:
    """Raise :class:`Interrupted` if a signal arrived whose exception was swallowed on the way."""
    if _PENDING:
        raise Interrupted(_PENDING[0], written=_COMMITS[0] > 0)


def _inside_a_temporary(target: Path) -> bool:
    with _TEMPS_LOCK:
        temps = {os.path.abspath(k) for k in _TEMPS}
    return any(str(p) in temps for p in Path(os.path.abspath(target)).parents)


def clear_interrupt() -> None:
    """Forget pending signals and commits (the command line calls it when a command starts)."""
    _PENDING.clear()
    _COMMITS[0] = 0


def _umask() -> int:
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def file_mode(existing: str | os.PathLike[str] | None = None) -> int:
    """The mode for a written file: that of ``existing`` if it is a file, else ``0666 & ~umask``."""
    if existing is not None:
        with contextlib.suppress(OSError):
            st = os.stat(existing)
            if not os.path.isdir(existing):
                return st.st_mode & 0o7777
    return 0o666 & ~_umask()


def dir_mode(existing: str | os.PathLike[str] | None = None) -> int:
    """The mode for a written folder: that of ``existing`` if it is a folder, else ``0777 & ~umask``."""
    if existing is not None and os.path.isdir(existing):
        return os.stat(existing).st_mode & 0o7777
    return 0o777 & ~_umask()


def _folder_of(target: Path) -> Path:
    return target.parent if str(target.parent) else Path(".")


def _remember(tmp: Path, target: Path) -> None:
    with _TEMPS_LOCK:
        _TEMPS[str(tmp)] = str(target)
        while len(_TEMPS) > _TEMPS_KEPT:  # the oldest go; an error is reported right after its cleanup
            _TEMPS.pop(next(iter(_TEMPS)))


def _forget(tmp: Path) -> None:
    """Nothing to do: a temporary is remembered after its removal, so the error that removed it can
    still be told in the user's terms (:func:`user_text`); the registry keeps the last few hundred."""


def user_text(text: str) -> str:
    """``text`` with every temporary path this module handed out replaced by its user-given target."""
    with _TEMPS_LOCK:
        pairs = sorted(_TEMPS.items(), key=lambda kv: -len(kv[0]))
    for tmp, target in pairs:
        text = text.replace(tmp, target)
        text = text.replace(os.path.basename(tmp), os.path.basename(target))
    return text


def _os_message(exc: OSError, target: Path, verb: str = "write") -> str:
    why = exc.strerror or str(exc) or type(exc).__name__
    return f"cannot {verb} {target}: {why}"


# --------------------------------------------------------------------------------------------------
# Single files


@contextlib.contextmanager
def atomic_output(path: str | os.PathLike[str], suffix: str | None = None) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; when the block ends without an exception and the file
    is not empty, give it the policy's mode and rename it over ``path``; otherwise delete it.

    The temporary keeps ``path``'s suffix (or ``suffix``) for writers that pick the format from the
    name (OpenCV's FileStorage and imwrite, matplotlib). ValueError (one line, naming ``path``) if
    the folder is missing, ``path`` is a folder, or nothing was written; OSError from the writer is
    re-raised naming ``path``, never the temporary.
    """
    target = Path(path)
    _check_file_target(target)
    tmp = _new_temp_file(target, suffix)
    try:
        try:
            yield tmp
        except OSError as e:
            raise OSError(e.errno, _os_message(e, target)) from None
        if not tmp.exists() or tmp.stat().st_size == 0:
            raise ValueError(f"writing {target} produced no data")
        _check_file_target(target)
        os.chmod(tmp, file_mode(target))
        with _signals_held():
            check_interrupt()
            try:
                os.replace(tmp, target)
            except OSError as e:
                raise OSError(e.errno, _os_message(e, target)) from None
            if not _inside_a_temporary(target):  # a file in a folder still being written is not an output yet
                _COMMITS[0] += 1
    finally:
        with contextlib.suppress(FileNotFoundError):
            tmp.unlink()
        _forget(tmp)


def atomic_write_bytes(path: str | os.PathLike[str], data: bytes) -> None:
    """Write ``data`` to ``path`` atomically (see :func:`atomic_output`)."""
    with atomic_output(path) as tmp:
        tmp.write_bytes(data)


def atomic_write_text(path: str | os.PathLike[str], text: str) -> None:
    """Write ``text`` (UTF-8, ``\\n`` line ends) to ``path`` atomically (see :func:`atomic_output`)."""
    with atomic_output(path) as tmp:
        with open(tmp, "w", encoding="utf-8", newline="\n") as fh:
            fh.write(text)


def revision(paths=("hdl", "tools/models")) -> str:
    """The commit a measurement belongs to: git's short HEAD of this checkout, with ``+`` when ``paths`` (the
    measured sources; default the HDL and its models) have uncommitted changes; ``?`` without git. The benches'
    tables (``eyestereo.sim.lib.runner.hdl_revision``) and the bitstream summary both name their commit so."""
    import subprocess

    root = Path(__file__).resolve().parents[1]
    try:
        head = subprocess.run(["git", "rev-parse", "--short", "HEAD"], cwd=root, capture_output=True,
                              text=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--", *paths], cwd=root, capture_output=True,
                               text=True).stdout.strip()
    except OSError:
        return "?"
    return (head or "?") + ("+" if dirty else "")


def write_section(doc: str | os.PathLike[str], text: str, begin: str, end: str) -> None:
    """Replace what stands between the markers ``begin`` and ``end`` of the page ``doc`` by ``text``
    (atomically; the markers stay). The measurement scripts fill their part of a page in ``docs/`` so;
    a page without the section stops them with a SystemExit that names the page and the markers."""
    old = Path(doc).read_text(encoding="utf-8")
    pattern = re.compile(re.escape(begin) + r".*?" + re.escape(end), re.S)
    if not pattern.search(old):
        raise SystemExit(f"{doc}: no '{begin}' ... '{end}' section to fill")
    atomic_write_text(doc, pattern.sub(lambda _m: f"{begin}\n{text}{end}", old))


def _check_file_target(target: Path) -> None:
    folder = _folder_of(target)
    if not folder.is_dir():
        raise ValueError(f"cannot write {target}: folder {folder} does not exist")
    if target.is_dir():
        raise ValueError(f"cannot write {target}: it is a folder")


def _new_temp_file(target: Path, suffix: str | None = None) -> Path:
    try:
        fd, name = tempfile.mkstemp(prefix=f".{target.name}{TMP_MARK}", suffix=suffix or target.suffix,
                                    dir=_folder_of(target))
    except OSError as e:
        raise OSError(e.errno, _os_message(e, target)) from None
    os.close(fd)
    tmp = Path(name)
    _remember(tmp, target)
    return tmp


# --------------------------------------------------------------------------------------------------
# A set of outputs, all or nothing


class Outputs:
    """The outputs of one command, written all or nothing.

    ::

        with Outputs() as out:
            calib_tmp = out.file("calib.yml")                  # checked now, before any work
            plots_tmp = out.folder("plots", owned=PLOT_NAMES)   # a fresh temporary folder to fill
            ... compute, write into calib_tmp and plots_tmp ...
        # here every target is in place; after an exception none has changed

    :meth:`file` and :meth:`folder` check their target at once (folder present, not the wrong kind,
    a folder only ours) and return the temporary to write. Leaving the ``with`` block normally
    commits: each target is checked again, then renamed into place (an existing one moved aside and
    deleted only after every rename succeeded; a failure puts every earlier target back). SIGINT and
    SIGTERM are held back during the renames; should a rename fail, every target renamed before it is put
back as it was. An exception in the block discards every temporary.
    """

    def __init__(self) -> None:
        self._items: list[tuple[Path, Path, str, Callable[[str], bool] | None]] = []
        self._open = True

    # -- registration -------------------------------------------------------------------------

    def file(self, target: str | os.PathLike[str], suffix: str | None = None) -> Path:
        """Register output file ``target``; returns the temporary path to write it to."""
        self._check_open()
        t = Path(target)
        self._check_unique(t)
        _check_file_target(t)
        tmp = _new_temp_file(t, suffix)
        self._items.append((t, tmp, "file", None))
        return tmp

    def folder(self, target: str | os.PathLike[str], owned: Callable[[str], bool] | Any = None, *,
               inputs: Any = ()) -> Path:
        """Register output folder ``target`` (created, or replaced as a whole); returns the empty
        temporary folder to fill. ``owned``: the names (a collection, a regular expression string or a
        predicate on a name) this command writes into it; an existing ``target`` holding anything
        else is refused. ``inputs``: the files (and folders) the command reads; a target that holds
        one of them is refused, even when its name is one the command writes (``sim harris`` reading
        ``out/left.png`` and writing ``out/``'s ``left.png``)."""
        self._check_open()
        t = Path(target)
        self._check_unique(t)
        pred = _owned_predicate(owned)
        check_output_folder(t, pred, inputs=inputs)
        try:
            tmp = Path(tempfile.mkdtemp(prefix=f".{t.name}{TMP_MARK}", dir=_folder_of(t)))
        except OSError as e:
            raise OSError(e.errno, _os_message(e, t)) from None
        _remember(tmp, t)
        self._items.append((t, tmp, "folder", pred))
        return tmp

    @property
    def targets(self) -> list[Path]:
        """The registered targets, in registration order."""
        return [t for t, _, _, _ in self._items]

    # -- the end ----------------------------------------------------------------------------------

    def __enter__(self) -> Outputs:
        return self

    def __exit__(self, exc_type: Any, exc: Any, tb: Any) -> None:
        if exc_type is None:
            self.commit()
        else:
            self.discard()

    def discard(self) -> None:
        """Remove every temporary; the targets stay as they were."""
        for _, tmp, _, _ in self._items:
            _remove(tmp)
            _forget(tmp)
        self._items = []
        self._open = False

    def commit(self) -> None:
        """Move every temporary into place, all or nothing (see the class docstring)."""
        self._check_open()
        with _signals_held():
            try:
                self._commit()
            finally:
                self.discard()

    def _commit(self) -> None:
        check_interrupt()
        for t, tmp, kind, pred in self._items:  # everything written and still allowed?
            if kind == "file":
                _check_file_target(t)
                if not tmp.exists() or tmp.stat().st_size == 0:
                    raise ValueError(f"writing {t} produced no data")
                os.chmod(tmp, file_mode(t))
            else:
                check_output_folder(t, pred)
                _normalise_modes(tmp)
                os.chmod(tmp, dir_mode(t))
        done: list[tuple[Path, Path | None]] = []  # (target, its old version kept aside, or None if new)
        try:
            for t, tmp, kind, _ in self._items:
                old = None
                if kind == "folder" and t.is_dir():
                    old = _aside(t)
                elif kind == "file" and t.exists():
                    old = _keep_copy(t)
                try:
                    os.replace(tmp, t) if kind == "file" else os.rename(tmp, t)
                except OSError as e:
                    if old is not None and kind == "folder":
                        os.rename(old, t)
                    elif old is not None:
                        old.unlink()
                    raise OSError(e.errno, _os_message(e, t)) from None
                done.append((t, old))
        except BaseException:
            for t, old in reversed(done):  # put every earlier target back as it was
                _remove(t)
                if old is not None:
                    os.replace(old, t) if not old.is_dir() else os.rename(old, t)
            raise
        _COMMITS[0] += 1
        for _, old in done:
            if old is not None:
                _remove(old)

    def _check_open(self) -> None:
        if not self._open:
            raise RuntimeError("this Outputs set is closed")

    def _check_unique(self, t: Path) -> None:
        for other in self.targets:
            a, b = Path(os.path.realpath(other)), Path(os.path.realpath(t))
            if a == b:
                raise ValueError(f"{t} is given as two different outputs")
            if a in b.parents or b in a.parents:
                inner, outer = (t, other) if a in b.parents else (other, t)
                raise ValueError(f"{inner} lies inside {outer}, another output of this command; give it "
                                 "another place")


def _owned_predicate(owned: Any) -> Callable[[str], bool]:
    if owned is None:
        return lambda name: False
    if callable(owned):
        return owned
    if isinstance(owned, str):
        rx = re.compile(owned)
        return lambda name: rx.fullmatch(name) is not None
    names = frozenset(owned)
    return lambda name: name in names


def check_output_folder(folder: str | os.PathLike[str], owned: Callable[[str], bool] | Any = None, *,
                        inputs: Any = ()) -> None:
    """ValueError unless ``folder`` may be (re)placed: it is named, its parent exists, it holds none of
    the command's ``inputs``, and it is missing, empty, or holds only files (and folders of files) whose
    names ``owned`` accepts."""
    t = Path(folder)
    pred = _owned_predicate(owned)
    if t.name in ("", ".", "..") or str(t) in (os.sep, "."):
        raise ValueError(f"the output folder must be named, e.g. {Path(t, 'out')}; got {str(t)!r}")
    parent = _folder_of(t)
    if not parent.is_dir():
        raise ValueError(f"cannot create {t}: folder {parent} does not exist")
    if t.is_symlink() or (t.exists() and not t.is_dir()):
        raise ValueError(f"{t} exists and is not a folder")
    check_not_inputs(t, inputs)
    if not t.exists():
        return
    for p in sorted(t.iterdir()):
        ok = not p.is_symlink() and pred(p.name)
        if ok and p.is_dir():
            ok = all(q.is_file() and not q.is_symlink() and pred(f"{p.name}/{q.name}") for q in p.iterdir())
        if not ok:
            raise ValueError(f"{t} holds {p.name}, which this command does not write; give a new or empty "
                             f"folder (an existing one is replaced as a whole)")


def check_not_inputs(folder: str | os.PathLike[str], inputs: Any) -> None:
    """ValueError when output ``folder`` is, or holds, one of the ``inputs`` (files or folders a command
    reads): replacing the folder would delete them. Paths are compared after resolving links."""
    t = Path(os.path.realpath(folder))
    for item in inputs or ():
        if item is None:
            continue
        p = Path(os.path.realpath(item))
        if p == t or t in p.parents:
            raise ValueError(f"{folder} holds {item}, an input of this command; give another output folder "
                             "(it would be replaced)")


def _aside(t: Path) -> Path:
    """Rename ``t`` to a fresh hidden name beside it; returns the new name."""
    old = Path(tempfile.mkdtemp(prefix=f".{t.name}{TMP_MARK}old-", dir=_folder_of(t)))
    os.rmdir(old)
    os.rename(t, old)
    return old


def _keep_copy(t: Path) -> Path:
    """A hidden second name (a hard link, else a copy) of file ``t``, so a replaced file can come back."""
    fd, name = tempfile.mkstemp(prefix=f".{t.name}{TMP_MARK}old-", dir=_folder_of(t))
    os.close(fd)
    keep = Path(name)
    try:
        os.unlink(keep)
        os.link(t, keep)
    except OSError:
        shutil.copy2(t, keep)
    return keep


def _remove(p: Path) -> None:
    if p.is_dir() and not p.is_symlink():
        shutil.rmtree(p, ignore_errors=True)
    else:
        with contextlib.suppress(FileNotFoundError):
            p.unlink()


def _normalise_modes(folder: Path) -> None:
    fmode, dmode = file_mode(), dir_mode()
    for p in folder.rglob("*"):
        if not p.is_symlink():
            os.chmod(p, dmode if p.is_dir() else fmode)


@contextlib.contextmanager
def _signals_held() -> Iterator[None]:
    """Hold SIGINT/SIGTERM/SIGHUP back (delivered afterwards) while renaming, where the OS allows it."""
    sigs = {signal.SIGINT, signal.SIGTERM} | ({signal.SIGHUP} if hasattr(signal, "SIGHUP") else set())
    can = hasattr(signal, "pthread_sigmask") and threading.current_thread() is threading.main_thread()
    if can:
        old = signal.pthread_sigmask(signal.SIG_BLOCK, sigs)
    try:
        yield
    finally:
        if can:
            signal.pthread_sigmask(signal.SIG_SETMASK, old)


# --------------------------------------------------------------------------------------------------
# Images in


_PNG_SIG = b"\x89PNG\r\n\x1a\n"
# what libjpeg/libpng/OpenCV print on stderr for a damaged file (their benign warnings are ignored)
_CORRUPT = re.compile(r"corrupt|premature end|bad huffman|invalid|unexpected|truncat|crc error|"
                      r"read error|not enough|incomplete|bogus|extraneous bytes|decompression error",
                      re.IGNORECASE)


def check_image_bytes(data: bytes, name: str, what: str = "image") -> None:
    """ValueError (naming ``name``) if ``data`` is an empty, truncated or corrupt PNG or JPEG file.

    PNG: the signature, every chunk's length and CRC, IHDR first, IEND last, and the IDAT stream
    must decompress to its end. JPEG: SOI first, an EOI marker after the last scan. Other formats pass
    (the decoder judges them).
    """
    name = f"{what} {name}"
    if len(data) == 0:
        raise ValueError(f"{name} is an empty file")
    if data.startswith(_PNG_SIG):
        _check_png(data, name)
    elif data.startswith(b"\xff\xd8"):
        if b"\xff\xd9" not in data[2:] or data.rfind(b"\xff\xd9") < data.rfind(b"\xff\xda"):
            raise ValueError(f"{name} is a truncated JPEG file (no end-of-image marker after the "
                             "last scan)")


def _check_png(data: bytes, name: str) -> None:
    pos, first, seen_end = len(_PNG_SIG), True, False
    z = zlib.decompressobj()
    idat_done = False
    while pos < len(data):
        if len(data) - pos < 12:
            raise ValueError(f"{name} is a truncated PNG file")
        length, ctype = struct.unpack(">I4s", data[pos:pos + 8])
        end = pos + 12 + length
        if end > len(data):
            raise ValueError(f"{name} is a truncated PNG file (chunk {ctype.decode('latin-1')!r} "
                             "is cut off)")
        body = data[pos + 8:pos + 8 + length]
        (crc,) = struct.unpack(">I", data[pos + 8 + length:end])
        if zlib.crc32(ctype + body) & 0xFFFFFFFF != crc:
            raise ValueError(f"{name} is a corrupt PNG file (CRC error in chunk "
                             f"{ctype.decode('latin-1')!r})")
        if first and ctype != b"IHDR":
            raise ValueError(f"{name} is a corrupt PNG file (no IHDR chunk first)")
        first = False
        if ctype == b"IDAT":
            try:
                z.decompress(body, 0)  # output discarded: only the stream's integrity matters here
            except zlib.error:
                raise ValueError(f"{name} is a corrupt PNG file (bad compressed data)") from None
            idat_done = z.eof
        if ctype == b"IEND":
            seen_end = True
            break
        pos = end
    if not seen_end:
        raise ValueError(f"{name} is a truncated PNG file (no IEND chunk)")
    if not idat_done:
        raise ValueError(f"{name} is a corrupt PNG file (its compressed pixel data ends early)")


@contextlib.contextmanager
def _captured_stderr() -> Iterator[list[str]]:
    """Collect what C libraries write to file descriptor 2 while the block runs (one item: the text)."""
    out: list[str] = []
    try:
        sys.stderr.flush()
    except (AttributeError, ValueError):
        pass
    try:
        saved = os.dup(2)
    except OSError:  # no descriptor 2 at all
        yield out
        return
    with tempfile.TemporaryFile() as f:
        os.dup2(f.fileno(), 2)
        try:
            yield out
        finally:
            os.dup2(saved, 2)
            os.close(saved)
            f.seek(0)
            out.append(f.read().decode("utf-8", "replace"))


def read_image(path: str | os.PathLike[str], *, what: str = "image", grey: bool = False) -> np.ndarray:
    """Read an image file as it is stored (``cv2.IMREAD_UNCHANGED``: grey (H, W), colour (H, W, 3/4)
    in BGR(A) order, any depth), refusing damaged files.

    ``grey=True``: a 2-D image in the file's depth; an 8-bit colour file is converted by its decoder
    exactly as ``cv2.imread(path, cv2.IMREAD_GRAYSCALE)`` does (what the benches and tests use), a
    16-bit one by ``cv2.cvtColor``. ValueError (one line, naming the file and calling it ``what``) when
    the file is missing, a folder, unreadable, empty, a truncated or corrupt PNG/JPEG, or nothing
    OpenCV can decode. The decoders' own messages never reach the terminal.
    """
    import cv2

    p = Path(path)
    if p.is_dir():
        raise ValueError(f"{what} {p} is a folder, not an image file")
    if not p.is_file():
        raise ValueError(f"{what} {p} does not exist")
    try:
        data = p.read_bytes()
    except OSError as e:
        raise ValueError(_os_message(e, p, "read")) from None
    check_image_bytes(data, str(p), what)
    with _captured_stderr() as said:
        try:
            img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_UNCHANGED)
        except cv2.error:
            img = None
    text = "".join(said)
    if img is None:
        raise ValueError(f"cannot read {what} {p}: not an image file OpenCV can decode")
    if _CORRUPT.search(text):
        first = next((ln.strip() for ln in text.splitlines() if _CORRUPT.search(ln)), "").rstrip(".")
        raise ValueError(f"{what} {p} is damaged (the decoder says: {first})")
    if img.ndim == 3 and img.shape[2] == 1:
        img = img[:, :, 0]
    if img.ndim not in (2, 3) or (img.ndim == 3 and img.shape[2] not in (3, 4)) or img.size == 0:
        raise ValueError(f"{what} {p} is not a grey or colour image (shape {img.shape})")
    if grey and img.ndim == 3:
        if img.dtype == np.uint8:
            with _captured_stderr():
                img = cv2.imdecode(np.frombuffer(data, np.uint8), cv2.IMREAD_GRAYSCALE)
        elif img.dtype == np.uint16:
            img = cv2.cvtColor(img, cv2.COLOR_BGRA2GRAY if img.shape[2] == 4 else cv2.COLOR_BGR2GRAY)
        else:
            img = img[..., :3].mean(axis=2).astype(img.dtype)  # refused by to_grey8 anyway
    return img


def to_grey8(images: np.ndarray | list[np.ndarray], names: str | list[str] = "image", *,
             order: str = "bgr") -> Any:
    """8-bit grey version(s) of images as :func:`read_image` returns them; one rule for every command.

    Colour (3 or 4 channels, ``order`` "bgr" or "rgb") becomes grey (OpenCV's weights); 8-bit stays;
    16-bit keeps its 8 most significant *used* bits: every image of the call is shifted right by the
    same amount, the smallest that brings the brightest pixel of all of them to 255 or below (a
    12-bit camera's data in 16-bit PNGs loses its 4 low bits, a full-range 16-bit image its 8). Other
    pixel types (floating point, signed) are refused with a ValueError naming the file: their scale
    is not known. A list in gives a list out (e.g. a stereo pair, which then shares one shift).
    """
    import cv2

    single = not isinstance(images, (list, tuple))
    imgs = [images] if single else list(images)
    labels = [names] * len(imgs) if isinstance(names, str) else list(names)
    out = []
    for img, name in zip(imgs, labels):
        a = np.asarray(img)
        if a.dtype not in (np.uint8, np.uint16):
            kind = "floating-point" if np.issubdtype(a.dtype, np.floating) else f"{a.dtype}"
            raise ValueError(f"{name} holds {kind} pixels; eyestereo reads 8- or 16-bit images (save it "
                             "as an 8- or 16-bit PNG)")
        if a.ndim == 3:
            codes = {("bgr", 3): cv2.COLOR_BGR2GRAY, ("bgr", 4): cv2.COLOR_BGRA2GRAY,
                     ("rgb", 3): cv2.COLOR_RGB2GRAY, ("rgb", 4): cv2.COLOR_RGBA2GRAY}
            if (order, a.shape[2]) not in codes:
                raise ValueError(f"{name} is not a grey or colour image (shape {a.shape})")
            a = cv2.cvtColor(np.ascontiguousarray(a), codes[(order, a.shape[2])])
        if a.ndim != 2:
            raise ValueError(f"{name} is not a grey or colour image (shape {a.shape})")
        out.append(a)
    deep = [a for a in out if a.dtype == np.uint16]
    if deep:
        top = max(int(a.max()) for a in deep)
        shift = max(0, top.bit_length() - 8)
        out = [(a >> shift).astype(np.uint8) if a.dtype == np.uint16 else a for a in out]
    return out[0] if single else out


def centre_crop(img: np.ndarray, width: int, height: int, name: str = "image") -> np.ndarray:
    """The ``width`` x ``height`` centre of ``img`` (a view); a ValueError naming ``name`` if it is smaller."""
    if img.shape[0] < height or img.shape[1] < width:
        raise ValueError(f"{name} is {img.shape[1]}x{img.shape[0]}, smaller than {width}x{height}")
    y0, x0 = (img.shape[0] - height) // 2, (img.shape[1] - width) // 2
    return img[y0:y0 + height, x0:x0 + width]
