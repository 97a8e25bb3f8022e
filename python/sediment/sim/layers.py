# SPDX-License-Identifier: GPL-2.0-or-later
"""Reader of the layer files written by the LAMMPS fix layers/hdf5.

Schema (version 1; lammps-pkg/SEDIMENT/doc/fix_layers_hdf5.rst): root attributes `schema`
("sediment-layers"), `schema_version`, `units`, `axis`, `dimension`, `cross_section`,
`layer_lo`, `layer_thickness`, `columns` (comma-separated), optional `slab_thickness`,
`particle_density`, `fluid_density`, `fluid_viscosity`, `fluid_yield_stress`; datasets
`layer_centre` [layers], `class_edges` [classes - 1], and per frame `time` [frames],
`step` [frames], `fraction` [frames, layers, columns] (solid volume fractions) and, in the files of a
fix with a fluid, `fluid` [frames, 2] (the fluid's density and viscosity when each frame was taken: a
deck re-issues the fluid as a temperature record goes).
"""
from __future__ import annotations

import faulthandler
import os
import pickle
import signal
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

SCHEMA = "sediment-layers"
SCHEMA_VERSION = 1


ATTRIBUTES = ("columns", "units", "axis", "dimension", "cross_section", "layer_lo", "layer_thickness")
DATASETS = ("time", "step", "fraction", "layer_centre", "class_edges")


class LayerFileError(ValueError):
    """A layer file that is missing, unreadable or of another schema."""


@dataclass
class LayerFile:
    """The frames of a layer file: solid fraction per layer (total and per column) over time, with the run's
    attributes."""

    path: Path
    units: str
    axis: str
    dimension: int
    cross_section: float            # area normal to the layers [length^2]
    layer_lo: float
    layer_thickness: float
    centres: np.ndarray             # layer centres [length]
    columns: list[str]              # "total", "class_k", "type_t"
    class_edges: np.ndarray         # diameters separating the size classes [length]
    time: np.ndarray                # [time] per frame
    step: np.ndarray
    fraction: np.ndarray            # [frames, layers, columns] solid volume fraction
    attributes: dict[str, float] = field(default_factory=dict)    # fluid/particle properties
    complete: bool = True           # False: the run writing it did not finish (killed, failed, still running)
    identity: dict[str, str] = field(default_factory=dict)         # run_id, code_version, run_start
    fluid: np.ndarray | None = None  # [frames, 2] the fluid's density and viscosity per frame; None: not recorded

    def column(self, name: str) -> np.ndarray:
        """Solid fraction of one column, [frames, layers]."""
        if name not in self.columns:
            raise KeyError(f"{self.path}: no column '{name}' (columns: {', '.join(self.columns)})")
        return self.fraction[:, :, self.columns.index(name)]

    @property
    def total(self) -> np.ndarray:
        """Total solid fraction per frame and layer."""
        return self.column("total")

    def solid_volume(self) -> np.ndarray:
        """Solid volume inside the layers per frame [length^3]."""
        return self.total.sum(axis=1) * self.layer_thickness * self.cross_section


def _text(value) -> str:
    return value.decode() if isinstance(value, bytes) else str(value)


def read_layers(path: str | Path) -> LayerFile:
    """Reads a layer file written by fix layers/hdf5, refusing files that are not one (LayerFileError)."""
    import h5py

    path = Path(path)
    if not path.is_file():
        raise LayerFileError(f"{path}: no such layer file")
    try:
        handle = h5py.File(path, "r")
    except OSError as exc:
        if "unable to lock file" in str(exc).lower():    # HDF5 locks a file it writes: a run writing its frames now
            raise LayerFileError(f"{path}: another process holds it open for writing (a run still writing its "
                                 "frames?): read it once that run has ended") from None
        raise LayerFileError(f"{path}: not a readable HDF5 file (truncated or corrupt?): {exc}") from None
    with handle as f:
        schema = _text(f.attrs.get("schema", ""))
        if schema != SCHEMA:
            if all(k in f for k in ("time", "fraction")) and "columns" in f.attrs:
                raise LayerFileError(f"{path}: damaged: it holds a layer file's datasets, but its schema attribute "
                                     f"reads '{schema[:40]}', not '{SCHEMA}'")
            raise LayerFileError(f"{path}: not a SEDIMENT layer file (schema '{schema}', expected '{SCHEMA}')")
        version = int(f.attrs.get("schema_version", -1))
        if version != SCHEMA_VERSION:
            raise LayerFileError(f"{path}: layer schema version {version}; this reader understands "
                                 f"version {SCHEMA_VERSION}")
        try:
            # The file's frames are those its writer counted as written whole (attribute `frames`, set
            # once they are flushed): a run killed or a disk filled while it wrote leaves the datasets
            # longer, their last frames torn (HDF5's fill value, a chunk half written). Files of earlier
            # versions have no count: the frames present in every dataset.
            frames = min(len(f[name]) for name in ("time", "step", "fraction", "fluid") if name in f)
            if "frames" in f.attrs:
                frames = min(frames, int(f.attrs["frames"]))
            fluid = np.asarray(f["fluid"][:frames], float) if "fluid" in f else None
            complete = f.attrs.get("complete", 0) == 1
            if frames == 0:
                raise LayerFileError(f"{path}: no frames (the run wrote none before it stopped)")
            columns = _text(f.attrs["columns"]).split(",")
            fraction = np.asarray(f["fraction"][:frames])
            if fraction.shape[1:] != (len(f["layer_centre"]), len(columns)):
                raise LayerFileError(f"{path}: fraction has shape {fraction.shape[1:]}, expected "
                                     f"({len(f['layer_centre'])}, {len(columns)})")
            extra = {k: float(f.attrs[k]) for k in ("slab_thickness", "particle_density", "fluid_density",
                                                     "fluid_viscosity", "fluid_yield_stress") if k in f.attrs}
            bad = [k for k, v in extra.items() if not (np.isfinite(v) and v >= 0)]
            if bad:
                raise LayerFileError(f"{path}: attribute {bad[0]} is {extra[bad[0]]}, not a physical value (corrupt file?)")
            # (a layer on a floor without a bed can hold more than its volume of parcels: no upper bound)
            if not np.all(np.isfinite(fraction)) or fraction.min() < 0:
                raise LayerFileError(f"{path}: negative or non-numeric solid fractions (corrupt frame data: "
                                     f"min {np.nanmin(fraction):.3g})")
            time = np.asarray(f["time"][:frames])
            if not np.all(np.isfinite(time)) or np.any(np.diff(time) <= 0):
                raise LayerFileError(f"{path}: frame times are not increasing (frames of two runs spliced, or corrupt)")
            if fluid is not None and (fluid.shape != (frames, 2) or not np.all(np.isfinite(fluid)) or fluid.min() <= 0):
                raise LayerFileError(f"{path}: the fluid of its frames is not a density and a viscosity > 0 per frame "
                                     "(corrupt frame data)")
            identity = {k: _text(f.attrs[k]) for k in ("run_id", "code_version", "run_start") if k in f.attrs}
            layers = LayerFile(path=path, units=_text(f.attrs["units"]), axis=_text(f.attrs["axis"]),
                             dimension=int(f.attrs["dimension"]), cross_section=float(f.attrs["cross_section"]),
                             layer_lo=float(f.attrs["layer_lo"]), layer_thickness=float(f.attrs["layer_thickness"]),
                             centres=np.asarray(f["layer_centre"]), columns=columns,
                             class_edges=np.asarray(f["class_edges"]), time=time,
                             step=np.asarray(f["step"][:frames]), fraction=fraction, attributes=extra,
                             complete=complete, identity=identity, fluid=fluid)
            check_content(layers)
            return layers
        except KeyError as exc:    # h5py's message names the attribute in one file format, not in the other
            missing = ([f"the attribute {k}" for k in ATTRIBUTES if k not in f.attrs]
                       + [f"the dataset {k}" for k in DATASETS if k not in f])
            what = missing[0] if missing else f"readable metadata ({exc})"
            raise LayerFileError(f"{path}: the layer file lacks {what} (damaged, or not written by fix "
                                 "layers/hdf5)") from None
        except OSError as exc:
            raise LayerFileError(f"{path}: unreadable layer data (truncated or corrupt?): {exc}") from None


UNIT_STYLES = ("si", "cgs", "micro", "nano", "real", "metal", "lj", "electron")    # LAMMPS's
# (attribute, quantity of sediment.plausible) of the physical attributes, checked in SI units
PHYSICAL = (("particle_density", "particle_density"), ("fluid_density", "fluid_density"),
            ("fluid_viscosity", "viscosity"), ("fluid_yield_stress", "yield_stress"))


def check_content(layers: LayerFile) -> None:
    """Refuses (LayerFileError) frames whose content cannot be a run's, wherever the file lies: names,
    shapes and geometry that disagree, physical attributes no grain or fluid has, size classes that do
    not add up to the total, a first frame without solids. (HDF5 checks each frame chunk's checksum as
    it reads it.)"""
    from ..plausible import RANGES

    path = layers.path

    def refuse(why: str) -> None:
        raise LayerFileError(f"{path}: {why}: damaged, or not written by fix layers/hdf5")
    names = layers.columns
    kinds = [n.split("_")[0] for n in names]
    if not names or names[0] != "total" or len(set(names)) != len(names) or not all(
            n == "total" or (k in ("class", "type") and n.split("_", 1)[1].isdigit()) for n, k in zip(names, kinds)):
        refuse(f"its columns attribute reads '{','.join(names)[:80]}', not 'total' then class_K and type_T columns")
    if layers.units not in UNIT_STYLES or layers.axis not in ("x", "y", "z") or layers.dimension not in (2, 3):
        refuse(f"units '{layers.units[:20]}', axis '{layers.axis[:5]}', dimension {layers.dimension}: not LAMMPS's")
    centres = layers.layer_lo + layers.layer_thickness * (np.arange(len(layers.centres)) + 0.5)
    if not (layers.layer_thickness > 0 and layers.cross_section > 0 and len(centres)
            and np.allclose(layers.centres, centres, rtol=1e-9, atol=1e-12 * abs(layers.layer_thickness))):
        refuse(f"its layers (layer_lo {layers.layer_lo:g}, layer_thickness {layers.layer_thickness:g}, cross_section "
               f"{layers.cross_section:g}) are not those of its layer_centre dataset")
    edges = np.asarray(layers.class_edges, float)
    classes = [k for k, kind in enumerate(kinds) if kind == "class"]
    if np.any(~np.isfinite(edges)) or np.any(edges <= 0) or np.any(np.diff(edges) <= 0) or (
            classes and len(classes) != len(edges) + 1):
        refuse(f"its {len(edges) + 1} size classes (class_edges) are not increasing diameters for its "
               f"{len(classes)} class columns")
    total = layers.fraction[:, :, 0]
    if classes:
        parts = layers.fraction[:, :, classes].sum(axis=2)
        off = np.abs(parts - total) > 1e-9 * np.maximum(total, 1e-12) + 1e-15
        if off.any():
            frame = int(np.argmax(off.any(axis=1)))
            refuse(f"the size classes' fractions do not add up to the total in frame {frame} "
                   f"(at {layers.time[frame]:g})")
    if not total[0].sum() > 0:
        refuse("its first frame holds no solids (every fraction 0)")
    steps = np.asarray(layers.step)
    if layers.time[0] < 0 or np.any(np.diff(steps) <= 0) or steps[0] < 0:
        refuse("its frames' times or steps do not run forward from the start")
    if layers.units == "si":
        for name, quantity in PHYSICAL:
            value = layers.attributes.get(name)
            limits = RANGES[quantity]
            if value is not None and not (limits.low <= value <= limits.high or value == 0 == limits.low):
                refuse(f"its {name} is {value:g} {limits.unit}, which no {quantity.replace('_', ' ')} is "
                       f"({limits.low:g}-{limits.high:g} {limits.unit}: {limits.why})")
        rho_p, rho_f = (layers.attributes.get(k) for k in ("particle_density", "fluid_density"))
        if rho_p is not None and rho_f is not None and not rho_p > rho_f:
            refuse(f"its grains ({rho_p:g} kg/m3) are not denser than its fluid ({rho_f:g} kg/m3)")


_SIGNATURE = b"\x89HDF\r\n\x1a\n"


def check_layer_file(path: str | Path) -> None:
    """Refuses (LayerFileError) a file that cannot be a whole HDF5 file, before HDF5 sees it: empty, without
    the HDF5 signature where the format puts it, a superblock of no known layout, or shorter than the
    end of file its superblock names (truncated)."""
    path = Path(path)
    if not path.is_file():
        raise LayerFileError(f"{path}: no such layer file")
    size = path.stat().st_size
    if size == 0:
        raise LayerFileError(f"{path}: the layer file is empty (0 bytes)")
    with open(path, "rb") as f:
        # the superblock sits at 0 or, after a user block, at 512, 1024, 2048, ... bytes
        at = 0
        while at + 8 <= size:
            f.seek(at)
            if f.read(8) == _SIGNATURE:
                break
            at = 512 if at == 0 else 2 * at
        else:
            raise LayerFileError(f"{path}: not an HDF5 file: no HDF5 signature at its start (damaged, or another kind "
                                 "of file)")
        head = f.read(56)
    version = head[0] if head else -1
    if version in (0, 1):
        offsets, lengths, eof_at = (head[5], head[6], 16 + (4 if version == 1 else 0)) if len(head) > 6 else (0, 0, 0)
        eof_at += 2 * offsets    # after the base and free-space addresses
    elif version in (2, 3):
        offsets, lengths = (head[1], head[2]) if len(head) > 2 else (0, 0)
        eof_at = 4 + 2 * offsets    # after the base and superblock-extension addresses
    else:
        raise LayerFileError(f"{path}: damaged HDF5 superblock (version {version}, which HDF5 never wrote)")
    if offsets not in (2, 4, 8) or lengths not in (2, 4, 8) or len(head) < eof_at + offsets:
        raise LayerFileError(f"{path}: damaged HDF5 superblock (addresses of {offsets} bytes, lengths of {lengths})")
    end = int.from_bytes(head[eof_at:eof_at + offsets], "little")
    if end > size - at:
        raise LayerFileError(f"{path}: truncated: {size} bytes, its HDF5 superblock says {end + at}")


def read_layers_guarded(path: str | Path) -> LayerFile:
    """`read_layers` in a child process, after `check_layer_file`: HDF5 may crash on a damaged file (a few
    bytes changed in its metadata), and the crash is then the child's, reported as a LayerFileError that
    names the file. Any other error while reading is reported as damage too."""
    check_layer_file(path)
    reader, writer = os.pipe()
    child = os.fork()
    if child == 0:    # the child: the frames or the reason, pickled, then out without clean-up
        code = 0
        try:
            os.close(reader)
            faulthandler.disable()    # a crash is the parent's one line, not a dump of this process
            try:
                answer = read_layers(path)
            except LayerFileError as exc:
                answer = exc
            except Exception as exc:    # h5py and numpy on damaged metadata: anything may come
                answer = LayerFileError(f"{path}: unreadable layer file (damaged?): {type(exc).__name__}: {exc}")
            with os.fdopen(writer, "wb") as out:
                pickle.dump(answer, out)
        except BaseException:
            code = 1
        os._exit(code)
    os.close(writer)
    with os.fdopen(reader, "rb") as answer_pipe:
        data = answer_pipe.read()
    _, status = os.waitpid(child, 0)
    if os.WIFSIGNALED(status):
        name = signal.Signals(os.WTERMSIG(status)).name
        raise LayerFileError(f"{path}: damaged: reading it crashed the HDF5 library ({name})")
    try:
        answer = pickle.loads(data)
    except Exception:
        raise LayerFileError(f"{path}: the process reading it ended without an answer (exit "
                             f"{os.waitstatus_to_exitcode(status)})") from None
    if isinstance(answer, LayerFileError):
        raise answer
    return answer
