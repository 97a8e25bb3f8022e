# SPDX-License-Identifier: GPL-2.0-or-later
"""Who may write what in a folder of results.

A command writes its results into a stage inside the output folder (``.sediment-stage-PID``) and
`OutputSet.publish` moves them into place together, under the folder's lock. The folder's manifest
(``.sediment-files.json``) records which command's set wrote each file, by its size and SHA-256 (a
copy of the folder keeps them; an edit does not). A command replaces or removes only files its own
earlier set wrote and nobody changed since, and never a file it reads.

A publish is journaled: ``.sediment-publishing.json`` is written before the first file moves, so a
command killed while moving files is completed by the next one that locks the folder, and until then
the journal names the new files. A command that fails or is interrupted before it publishes leaves
the folder as it was.
"""
from __future__ import annotations

import datetime
import fcntl
import hashlib
import json
import os
import shutil
import signal
import threading
from contextlib import contextmanager
from pathlib import Path
from typing import Iterable, Iterator

from .results import write_text

LOCK = ".sediment.lock"                    # one sediment command at a time writes into a folder
MANIFEST = ".sediment-files.json"
JOURNAL = ".sediment-publishing.json"
STAGE = ".sediment-stage-"
_OWN = ".sediment"                         # the folders' own bookkeeping: never part of a result
_FORMAT = 2    # 2: with the checksum of its sets


@contextmanager
def exclusive(path: Path, busy: str) -> Iterator[None]:
    """Holds an exclusive lock on the file `path` (created, holding this process's id) for the block;
    RuntimeError naming the holder and `busy` (what to do) if another process has it."""
    with open(path, "a+") as handle:
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            handle.seek(0)
            raise RuntimeError(f"another sediment command (pid {handle.read().strip() or '?'}) is using "
                               f"{path.parent}; {busy}") from None
        handle.seek(0)
        handle.truncate()
        handle.write(str(os.getpid()))
        handle.flush()
        yield


def folder_lock(folder: Path, what: str):
    """The lock of `folder` (created if needed): one sediment command at a time works there."""
    folder = Path(folder)
    if folder.exists() and not folder.is_dir():
        raise ValueError(f"{folder} exists and is not a folder")
    folder.mkdir(parents=True, exist_ok=True)
    return exclusive(folder / LOCK, f"wait for it, or {what} in another folder")


class OutputSet:
    """The files one command writes into `folder`, published as one set.

    Use as a context manager: it takes the folder's lock, completes a publish an earlier command left
    midway, and gives a fresh `stage` to write into; `publish()` moves the set into place. Leaving
    the block without publishing removes the stage and leaves the folder as it was.

    Parameters
    ----------
    folder : Path
        The output folder (created).
    name : str
        The set's name in the manifest, the command that writes it (``invert``, ``paste funnel``): a
        new set of that name replaces the previous one.
    inputs : iterable of Path
        Files the command reads: the set may not replace or remove them.
    """

    def __init__(self, folder: Path, name: str, inputs: Iterable[Path] = ()) -> None:
        self.folder = Path(folder)
        self.name = name
        self.inputs = [Path(p) for p in inputs]
        self.stage = self.folder / f"{STAGE}{os.getpid()}"
        self.published = False
        self._foreign: list[str] = []
        self.removed_sets: list[tuple[str, Path]] = []    # sets (name, folder) removed with what they were made from
        self.dropped: list[str] = []    # the previous set's entries this one did not write again, removed with it
        self.removed_also: list[str] = []    # the files of the folder asked to go with it (remove_also)
        self._created = [p for p in (self.folder, *self.folder.parents) if not p.exists()]
        self._lock = folder_lock(self.folder, "write")

    def __enter__(self) -> OutputSet:
        self._lock.__enter__()
        try:
            settle(self.folder)
            shutil.rmtree(self.stage, ignore_errors=True)
            self.stage.mkdir()
        except BaseException as exc:
            self._lock.__exit__(type(exc), exc, exc.__traceback__)
            raise
        return self

    def __exit__(self, kind, exc, traceback) -> None:
        try:
            if not _journal_names(self.folder, self.stage):    # a publish cut short keeps its stage for settle()
                shutil.rmtree(self.stage, ignore_errors=True)
        finally:
            self._lock.__exit__(kind, exc, traceback)
        if not self.published:    # a folder made for this command only is not left behind empty
            for folder in self._created:
                (folder / LOCK).unlink(missing_ok=True)
                try:
                    folder.rmdir()
                except OSError:
                    break
        if isinstance(exc, OSError) and not self.published:
            raise OSError(exc.errno, f"{exc.strerror or exc} ({_shown(exc.filename, self)}); nothing of this "
                          f"sediment {self.name} was published: {self.folder} is as it was") from exc

    def remove_also(self, names: Iterable[str]) -> None:
        """Files of the folder, not this set's, that the user asked to have removed with it (by path
        relative to the folder); removed when the set is published."""
        self._foreign += [str(n) for n in names]
        self.removed_also += [str(n) for n in names]

    def publish(self) -> list[Path]:
        """Moves the staged set into the folder, replacing this set's previous files. ValueError, with
        nothing moved, if that would replace or remove a file this set did not write or an input.
        Returns the folder's entries written (files and folders)."""
        new = _files(self.stage)
        entries = sorted({_entry(r) for r in new})
        manifest = read_manifest(self.folder)
        sets = manifest["sets"]
        old = sets.get(self.name, {}).get("files", {})
        touched = set(entries) | {_entry(r) for r in old}
        self._refuse_foreign(touched, old, sets)
        self._refuse_inputs(touched | {_entry(r) for r in self._foreign})
        self._derived(sets)
        now = datetime.datetime.now().astimezone().isoformat(timespec="seconds")
        sets[self.name] = {"written": now, "files": new,
                           "inputs": [os.path.relpath(p.resolve(), self.folder.resolve())
                                      for p in self.inputs if p.is_file()]}
        for other in sets.values():
            other["files"] = {r: i for r, i in other["files"].items() if _entry(r) not in self._foreign}
        sets = {k: v for k, v in sets.items() if v["files"] or k == self.name}
        manifest["sets"] = sets
        (self.stage / MANIFEST).write_text(manifest_text(manifest))
        self.dropped = sorted(touched - set(entries))
        journal = {"set": self.name, "stage": self.stage.name, "move": entries,
                   "remove": self.dropped + self._foreign}
        (self.stage / JOURNAL).write_text(json.dumps(journal) + "\n")
        with signals_held():    # Ctrl-C waits until every file is in place
            os.rename(self.stage / JOURNAL, self.folder / JOURNAL)
            self.published = True
            _complete(self.folder, journal)
        for name, below in self.removed_sets:    # their files are gone; so goes their record below
            if below != self.folder:
                record = read_manifest(below)
                record["sets"].pop(name, None)
                write_text(below / MANIFEST, manifest_text(record))
        return [self.folder / e for e in entries]

    def _derived(self, sets: dict) -> None:
        """Adds to the files removed with the set the sets made from them, in the folder and in the
        folders below it (a readout of a run's frames goes with the frames)."""
        gone = {(self.folder / r).resolve() for r in self._foreign}
        if not gone:
            return

        def made_from_gone(where: Path, content: dict) -> bool:
            return any((where / r).resolve() in gone for r in content.get("inputs", []))

        for name, other in sets.items():
            if name != self.name and made_from_gone(self.folder, other):
                self._foreign += sorted({_entry(r) for r in other["files"]} - set(self._foreign))
                self.removed_sets.append((name, self.folder))
        for manifest in sorted(self.folder.glob(f"*/**/{MANIFEST}")):
            below = manifest.parent
            if any(part.startswith(_OWN) for part in below.relative_to(self.folder).parts):
                continue
            for name, other in read_manifest(below)["sets"].items():
                if made_from_gone(below, other):
                    where = below.relative_to(self.folder)
                    self._foreign += sorted({str(where / _entry(r)) for r in other["files"]} - set(self._foreign))
                    self.removed_sets.append((name, below))

    def _refuse_foreign(self, touched: set[str], old: dict, sets: dict) -> None:
        owners = {r: name for name, s in sets.items() if name != self.name for r in s.get("files", {})}
        foreign = []
        for entry in sorted(touched):
            for rel, identity in _files(self.folder / entry, entry).items():
                if old.get(rel) == identity:
                    continue
                why = ("written by sediment " + owners[rel] if rel in owners else
                       "changed since sediment " + self.name + " wrote it" if rel in old else
                       "not written by sediment " + self.name)
                foreign.append(f"{self.folder / rel} ({why})")
        if foreign:
            more = f" and {len(foreign) - 3} more" if len(foreign) > 3 else ""
            raise ValueError(f"this sediment {self.name} would replace or remove files it did not write: "
                             f"{', '.join(foreign[:3])}{more}; move them, or choose another --out")

    def _refuse_inputs(self, touched: set[str]) -> None:
        here = self.folder.resolve()
        for path in self.inputs:
            try:
                rel = path.resolve().relative_to(here)
            except ValueError:
                continue
            if rel.parts and rel.parts[0] in touched:
                raise ValueError(f"{path} is an input of this sediment {self.name} and its results would replace "
                                 "it: choose another --out")


def _checksum(sets: dict) -> str:
    return hashlib.sha256(json.dumps(sets, sort_keys=True).encode()).hexdigest()


def manifest_text(manifest: dict) -> str:
    """A manifest as written: with the checksum of its sets, so that one edited by hand is not trusted."""
    return json.dumps({**manifest, "format": _FORMAT, "checksum": _checksum(manifest["sets"])}) + "\n"


def read_manifest(folder: Path) -> dict:
    """The folder's manifest (empty if it has none); ValueError naming it if it is damaged."""
    path = Path(folder) / MANIFEST
    if not path.exists():
        return {"format": _FORMAT, "sets": {}}
    try:
        manifest = json.loads(path.read_text())
        sets = manifest["sets"]
        if not isinstance(sets, dict):
            raise ValueError
        for name, content in sets.items():
            files = content["files"]
            if not (isinstance(name, str) and isinstance(files, dict) and all(map(_inside, files))
                    and all(isinstance(i, list) and len(i) == 2 for i in files.values())):
                raise ValueError
    except (ValueError, KeyError, TypeError, UnicodeDecodeError):
        raise ValueError(f"{path} is damaged: it records which sediment command wrote each file of {folder}; "
                         "delete it only if no file there needs protecting (commands then refuse to replace "
                         "any file of the folder)") from None
    # (a manifest of format 1 has no checksum: it is taken as written, and gets one when next written)
    if manifest.get("format", 1) != 1 and manifest.get("checksum") != _checksum(sets):
        raise ValueError(f"{path} was edited (its checksum fails): it records which sediment command wrote each file "
                         f"of {folder}, and a command removes the files it names; put back the one sediment wrote, or "
                         "delete it only if no file there needs protecting (commands then refuse to replace any file "
                         "of the folder)")
    return manifest


def settle(folder: Path) -> None:
    """Completes a publish a killed command left midway, and removes the stages of processes that
    died. Call with the folder's lock held."""
    folder = Path(folder)
    journal_path = folder / JOURNAL
    if journal_path.exists():
        try:
            journal = json.loads(journal_path.read_text())
            if not (isinstance(journal["stage"], str) and journal["stage"].startswith(STAGE) and "/" not in journal["stage"]
                    and all(map(_inside, journal["move"] + journal["remove"]))):
                raise ValueError
        except (ValueError, KeyError, TypeError, UnicodeDecodeError):
            raise ValueError(f"{journal_path} is damaged: a sediment command was killed while it moved its "
                             "results into place; the folder may hold a mix of two results") from None
        _complete(folder, journal)
    for stage in folder.glob(STAGE + "*"):
        pid = stage.name[len(STAGE):]
        if not (pid.isdigit() and Path(f"/proc/{pid}").exists()):
            shutil.rmtree(stage, ignore_errors=True)


def _complete(folder: Path, journal: dict) -> None:
    """Carries out a journaled publish; each step is skipped if done, so it may be repeated."""
    stage = folder / journal["stage"]
    trash = stage / f"{_OWN}-replaced"

    def discard(path: Path, name: str) -> None:
        if path.is_dir() and not path.is_symlink():
            trash.mkdir(parents=True, exist_ok=True)
            aside = trash / name.replace("/", "%")
            shutil.rmtree(aside, ignore_errors=True)
            os.rename(path, aside)    # at once; deleted with the stage
        else:
            path.unlink(missing_ok=True)

    for entry in journal["move"]:
        source, target = stage / entry, folder / entry
        if os.path.lexists(source):
            if os.path.lexists(target) and (target.is_dir() or source.is_dir()):
                discard(target, entry)
            os.replace(source, target)
    for name in journal["remove"]:
        discard(folder / name, name)
    if (stage / MANIFEST).exists():
        os.replace(stage / MANIFEST, folder / MANIFEST)
    (folder / JOURNAL).unlink(missing_ok=True)
    shutil.rmtree(stage, ignore_errors=True)


def _journal_names(folder: Path, stage: Path) -> bool:
    """Whether the folder's journal is that of `stage` (a publish begun and not completed)."""
    try:
        return json.loads((folder / JOURNAL).read_text()).get("stage") == stage.name
    except (OSError, ValueError, AttributeError):
        return False


def _files(root: Path, prefix: str = "") -> dict[str, list]:
    """Every file and link under `root` (or `root` itself) by path relative to it (after `prefix`):
    its size and SHA-256 (of a link, of its target's name). The folders' bookkeeping is left out."""
    def identity(path: str) -> list:
        if os.path.islink(path):
            return [0, hashlib.sha256(os.fsencode(os.readlink(path))).hexdigest()]
        digest = hashlib.sha256()
        with open(path, "rb") as handle:
            for block in iter(lambda: handle.read(1 << 20), b""):
                digest.update(block)
        return [os.path.getsize(path), digest.hexdigest()]

    if not os.path.lexists(root):
        return {}
    if root.is_symlink() or not root.is_dir():
        return {prefix or root.name: identity(str(root))}
    found = {}
    for where, folders, files in os.walk(root):
        folders[:] = [f for f in folders if not f.startswith(_OWN)]
        base = os.path.join(prefix, os.path.relpath(where, root)) if prefix else os.path.relpath(where, root)
        for name in files:
            if not name.startswith(_OWN):
                found[os.path.normpath(os.path.join(base, name))] = identity(os.path.join(where, name))
    return found


def _inside(relative: object) -> bool:
    """Whether a path of the bookkeeping names a file inside the folder (a forged '../x' does not)."""
    return (isinstance(relative, str) and relative != "" and not os.path.isabs(relative)
            and os.path.normpath(relative) == relative and relative.split("/")[0] not in ("..", ".")
            and not relative.startswith(_OWN))


def _entry(relative: str) -> str:
    """The folder's entry (file or first folder) a relative path lies in."""
    return relative.split("/", 1)[0]


def _shown(filename: object, outputs: OutputSet) -> str:
    """A file of the stage as the path it was to have in the folder."""
    if not filename:
        return str(outputs.folder)
    try:
        return str(outputs.folder / Path(str(filename)).relative_to(outputs.stage))
    except ValueError:
        return str(filename)


@contextmanager
def signals_held() -> Iterator[None]:
    """SIGINT and SIGTERM held back for the block and raised after it. Python's handlers, not the
    signal mask: the mask is per thread, and a process's signal may land in another thread."""
    if threading.current_thread() is not threading.main_thread():    # only the main thread sets handlers
        yield
        return
    caught: list[int] = []
    previous = {sig: signal.signal(sig, lambda number, _frame: caught.append(number))
                for sig in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for sig, handler in previous.items():
            signal.signal(sig, handler)
        if caught:
            signal.raise_signal(caught[0])
