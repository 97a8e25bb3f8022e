# SPDX-License-Identifier: GPL-2.0-or-later
"""What a run is, and whether what is in its folder is still what it made: the run id (its inputs'
hash, its variables' and a token of its start), the folder's run record, the digests of the files a
run started with and wrote, whether a layer file finished and a restart file belongs to the run, and
the checks that refuse frames read against another test's inputs."""
from __future__ import annotations

import hashlib
import json
import re
import secrets
import sys
from pathlib import Path

from ..results import write_text


RECORD = ".sediment-run.json"    # the folder's latest run: its identity, deck, variables and state
RUN_OUTPUTS = ("restart.a.bin", "restart.b.bin", "restart.a.bin.crc32", "restart.b.bin.crc32", "log.lammps",
               "log.failed.lammps", RECORD)
# Tables beside a run that it does not read but that its readout compares its frames with.
COMPARED = ("input_psd.csv", "simulated_psd.csv")


# Commands whose first literal argument (after an ID for molecule) is a file the deck reads.
_READS = re.compile(r"^\s*(?:read_data|include|read_dump|molecule\s+\S+)\s+([^\s$\"']+)", re.MULTILINE)


def input_files(deck: Path) -> list[Path]:
    """The files a deck reads besides itself: the literal names after read_data, include, read_dump and
    molecule (also inside an if's quoted commands) that exist beside it. Names built from variables
    cannot be known before the run and are not covered."""
    text = Path(deck).read_text(errors="replace").replace('"', "\n")
    names = dict.fromkeys(m.group(1) for m in _READS.finditer(text))
    return [Path(deck).parent / n for n in names if (Path(deck).parent / n).is_file()]


def inputs_id(deck: Path) -> str:
    """A hash of what a deck reads: its text (without whole-line comments, which `sediment sample`
    dates) and every file of `input_files`, each with its name."""
    digest = hashlib.sha256()
    deck = Path(deck)
    for path in [deck, *input_files(deck)]:
        data = path.read_bytes()
        if path == deck:
            data = b"\n".join(line for line in data.splitlines() if not line.lstrip().startswith(b"#"))
        digest.update(f"{path.name}\0{len(data)}\0".encode() + data)
    return digest.hexdigest()[:12]


def layer_file_of(deck: Path, variables: dict[str, str]) -> Path | None:
    """The layer file a deck's fix layers/hdf5 writes (its name from -var or an index/string variable of
    the deck), or None if it has none or its name cannot be known before the run."""
    text = Path(deck).read_text(errors="replace")
    found = re.search(r"^\s*fix\s+\S+\s+\S+\s+layers/hdf5\s+\S+\s+(\S+)", text, re.MULTILINE)
    if found is None:
        return None
    name = found.group(1)
    reference = re.fullmatch(r"\$\{(\w+)\}|\$(\w)", name)
    if reference:
        key = reference.group(1) or reference.group(2)
        defined = re.search(rf"^\s*variable\s+{key}\s+(?:index|string)\s+(\S+)", text, re.MULTILINE)
        name = variables.get(key) or (defined.group(1) if defined else None)
    if not name or "$" in name:
        return None
    return Path(deck).parent / name


def unresumable(deck: Path, variables: dict[str, str]) -> bool:
    """Whether the deck's folder holds the frames of an interrupted run that wrote no restart file: no
    --resume can continue them, so a new start replaces them without --force (and says so)."""
    layers = layer_file_of(deck, variables)
    partial = layers.with_name(layers.name + ".partial") if layers is not None else None
    if partial is None or not partial.exists() or any((deck.parent / n).exists() for n in RUN_OUTPUTS[:2]):
        return False
    print(f"{partial.name}: frames of an interrupted run that wrote no restart file, which no --resume can "
          "continue: starting anew over them", file=sys.stderr)
    return True


def stamp(layers: Path | None) -> tuple:
    """What says whether a run touched its frames: the layer file's and its .partial's size and time."""
    if layers is None:
        return ()
    return tuple((p.stat().st_size, p.stat().st_mtime_ns) if p.exists() else None
                 for p in (layers, layers.with_name(layers.name + ".partial")))


def finished(layers: Path, identity: str) -> bool:
    """Whether `layers` is complete and of the run `identity`, with no frames of it left partial."""
    import h5py

    if not identity or not layers.is_file() or layers.with_name(layers.name + ".partial").exists():
        return False
    try:
        with h5py.File(layers, "r") as f:
            held = f.attrs.get("run_id", b"")
            return f.attrs.get("complete", 0) == 1 and (held.decode() if isinstance(held, bytes) else held) == identity
    except OSError:
        return False


def file_digest(path: Path) -> str:
    """The SHA-256 of a file's bytes, in hexadecimal."""
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            digest.update(block)
    return digest.hexdigest()


def restart_damage(restart: Path, identity: str) -> str | None:
    """Why a restart file does not match the checksum fix layers/hdf5 wrote beside it once LAMMPS had
    closed it (NAME.crc32), or None if it matches; one that does not name the run `identity` (which
    fix layers/hdf5 stores in it) is said to be another run's."""
    import zlib

    sums = restart.with_name(restart.name + ".crc32")
    if not sums.is_file():
        return f"no checksum beside it ({sums.name}): the run was stopped before it recorded one"
    try:
        words = sums.read_text().split()
        held = dict(zip(words[::2], words[1::2]))
        crc, size = int(held["crc32"], 16), int(held["size"])
    except (ValueError, KeyError, UnicodeDecodeError):
        return f"its checksum file {sums.name} is damaged"
    if restart.stat().st_size != size:
        return (f"{restart.stat().st_size} bytes, {size} when it was last written ({sums.name}): damaged, or being "
                "written when the run was stopped")
    found, named = 0, False
    with open(restart, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            found = zlib.crc32(block, found)
            named = named or identity.encode() in block    # in the fix's state, before the atoms
    if found != crc and not named:
        return f"it does not name the interrupted run {identity}: a restart file of another run, or damaged"
    if found != crc:
        return (f"its bytes differ from those it was last written with (CRC-32 {found:08x}, {sums.name} says "
                f"{crc:08x}): damaged, or being written when the run was stopped")
    return None


def run_id(deck: Path, variables: dict[str, object]) -> str:
    """A new run's identity, INPUTS-VARIABLES-START: the hash of what the deck reads (`inputs_id`), of
    its variables, and a token of this start. Stored in the layer file and in each restart file: a
    resumed run continues only the frames and restart files of the start it resumes."""
    digest = hashlib.sha256()
    for name, value in sorted(variables.items()):
        digest.update(f"\0{name}={value}".encode())
    return f"{inputs_id(deck)}-{digest.hexdigest()[:6]}-{secrets.token_hex(4)}"


def already_finished(deck: Path, variables: dict[str, str]) -> Path | None:
    """The complete layer file of the folder's finished run of this deck, as it reads now and with these
    variables (a rerun would only write it again), or None."""
    try:
        record = read_record(deck.parent)
    except ValueError:
        return None
    layers = layer_file_of(deck, variables)
    if (record is None or layers is None or record.get("state") != "finished" or record.get("deck") != deck.name
            or record.get("variables") != variables or inputs_of_run(record["run_id"]) != inputs_id(deck)):
        return None
    return layers if finished(layers, record["run_id"]) else None


def inputs_of_run(identity: str) -> str | None:
    """The INPUTS part of a run id (`run_id`), or None for an id not of that form (a run of an older
    SEDIMENT, or none)."""
    parts = identity.split("-")
    return parts[0] if len(parts) == 3 else None


def read_record(folder: Path) -> dict | None:
    """The folder's run record (None if there is none); ValueError if it is damaged."""
    path = Path(folder) / RECORD
    if not path.is_file():
        return None
    try:
        record = json.loads(path.read_text())
        if not isinstance(record, dict) or not {"run_id", "deck", "state"} <= record.keys():
            raise ValueError("fields missing")
        return record
    except (ValueError, UnicodeDecodeError) as exc:
        raise ValueError(f"{path} is damaged ({exc}); remove it, and run the deck anew with --force") from None


def write_record(folder: Path, **record) -> None:
    """Writes the folder's run record (RECORD), replacing the one before."""
    write_text(folder / RECORD, json.dumps(record, indent=1) + "\n")


def resume_id(deck: Path, variables: dict[str, str]) -> str:
    """The identity of the interrupted run in the deck's folder, after checking that it can be resumed:
    it did not finish, it ran this deck, and what the deck reads has not changed since."""
    folder = deck.parent
    record = read_record(folder)
    if record is None or record.get("deck") != deck.name:
        raise ValueError(f"nothing to resume in {folder}: no interrupted run of {deck.name} is recorded there "
                         f"({RECORD}); run it without --resume")
    if record["state"] == "finished":
        raise ValueError(f"the run of {deck.name} in {folder} finished: nothing to resume; run it again with --force")
    if record["run_id"].split("-")[0] != inputs_id(deck):
        raise ValueError(f"{_what_changed(deck, record.get('files', {}))} since the interrupted run started: its "
                         "restart files are of other inputs; put them back as they were, or start the run anew with "
                         "--force")
    if record.get("variables", {}) != variables:
        raise ValueError(f"the interrupted run had the variables {record.get('variables')}, this one {variables}: "
                         "resume it with the same --var options")
    return record["run_id"]


def check_written(deck: Path) -> None:
    """Refuses a deck that reads a file `sediment sample` wrote beside it whose bytes have changed since
    (its size and SHA-256 in the folder's manifest): a damaged data file may read as no atoms at all."""
    from ..folders import read_manifest

    written = read_manifest(deck.parent)["sets"].get("sample", {}).get("files", {})
    for path in input_files(deck):
        held = written.get(path.name)
        if held is not None and [path.stat().st_size, file_digest(path)] != held:
            raise ValueError(f"{path} changed since sediment sample wrote it ({path.stat().st_size} bytes, "
                             f"{held[0]} then): damaged, or edited; write it again (sediment sample --force)")


def _what_changed(deck: Path, started: dict[str, str]) -> str:
    """Which of the files a run started with (the record's names and SHA-256) are gone or changed, and which
    the deck reads now that it did not, as a message's start."""
    if deck.name not in started:    # a record of another run, or damaged
        return (f"the run record ({RECORD}) names no start of {deck.name} (damaged, or of another run), and "
                f"{deck.name} or a file it reads changed")
    now = [deck, *input_files(deck)]
    gone = [n for n in started if n not in COMPARED and not (deck.parent / n).is_file()]
    changed = [p.name for p in now if p.name in started and file_digest(p) != started[p.name]]
    new = [p.name for p in now if p.name not in started]
    parts = ([f"{', '.join(changed)} changed"] if changed else []) + ([f"{', '.join(gone)} deleted"] if gone else []) \
        + ([f"{deck.name} now reads {', '.join(new)}"] if new else [])
    return "; ".join(parts) if parts else f"{deck.name} or a file it reads changed (the run record names no files)"


def check_partial(deck: Path, variables: dict[str, str], identity: str) -> None:
    """Refuses to resume frames that do not read back whole (read by a child process: HDF5 may crash on
    a damaged file), or that another run wrote: the run would continue them into a result no one can
    read, or into a splice."""
    from .layers import LayerFileError, read_layers_guarded

    layers = layer_file_of(deck, variables)
    partial = layers.with_name(layers.name + ".partial") if layers is not None else None
    if partial is None or not partial.exists():
        return    # fix layers/hdf5 says which frames are gone
    try:
        held = read_layers_guarded(partial).identity.get("run_id", "")
    except LayerFileError as exc:
        raise ValueError(f"cannot resume: the interrupted run's frames are damaged: {exc}; start the run anew with "
                         "--force") from None
    if held and held != identity:
        raise ValueError(f"cannot resume: {partial} holds the frames of run {held}, not those of the interrupted run "
                         f"{identity} (put there since?); start the run anew with --force")


def check_digest(path: Path) -> None:
    """Refuses a layer file whose bytes are not those its run recorded when it completed it (in the
    folder's run record): damaged, or replaced since."""
    record = read_record(path.parent)
    done = (record or {}).get("layers", {})
    if done.get("file") == path.name and file_digest(path) != done.get("sha256"):
        raise ValueError(f"{path} is damaged or was replaced: its bytes are not those its run {record['run_id']} "
                         f"completed (SHA-256 in {path.parent / RECORD}); run the deck again (sediment run --force)")


def check_inputs(path: Path, identity: str, compared: list[Path] = ()) -> None:
    """Refuses a layer file beside a deck whose inputs are not those of the run that wrote it (the
    folder sampled again since), or beside tables (`compared`) other than those its run started with:
    its frames would be read against another test's. The run record names what differs."""
    record = read_record(path.parent)
    deck = path.parent / (record["deck"] if record else "in.sedimentation")
    held = inputs_of_run(identity)
    started = record.get("files", {}) if record and record["run_id"] == identity else {}
    changed = [p.name for p in [deck, *(input_files(deck) if deck.is_file() else []), *compared]
               if p.name in started and (not p.is_file() or file_digest(p) != started[p.name])]
    if held is not None and deck.is_file() and inputs_id(deck) != held:
        reads = ", ".join([deck.name] + [p.name for p in input_files(deck)])
        which = f"; {', '.join(changed)} changed since it started" if changed else ""
        raise ValueError(f"{path} was written by a run of other inputs than those now in its folder ({reads}{which}): "
                         "it was sampled again since, and its tables describe another test; run the deck again, or "
                         "read the frames where their own tables are")
    if changed:
        raise ValueError(f"{', '.join(changed)} beside {path} changed since its run started (replaced, by another "
                         f"sample's for one; {RECORD} holds the SHA-256 of what the run started with): the frames "
                         "would be compared with another test's tables; put the run's own back, or give --psd and "
                         "--simulated")
