# SPDX-License-Identifier: GPL-2.0-or-later
"""sediment.layers: the reader of fix layers/hdf5 files, on good and bad files."""
from pathlib import Path

import numpy as np
import pytest

h5py = pytest.importorskip("h5py")

from sediment.sim.layers import LayerFileError, read_layers  # noqa: E402


def write_layer_file(path: Path, frames: int = 3, version: int = 1, schema: str = "sediment-layers",
                     cut_last_fraction: bool = False) -> None:
    n, columns = 10, ["total", "class_0", "class_1"]
    with h5py.File(path, "w") as f:
        f.attrs.update(schema=schema, schema_version=version, units="si", axis="z", dimension=3,
                       cross_section=1e-6, layer_lo=0.0, layer_thickness=1e-3, columns=",".join(columns),
                       particle_density=2650.0, fluid_density=998.2, fluid_viscosity=1.002e-3)
        f["layer_centre"] = (np.arange(n) + 0.5) * 1e-3
        f["class_edges"] = np.array([2e-5])
        f["time"] = np.arange(frames) * 0.5
        f["step"] = np.arange(frames) * 50
        fraction = np.zeros((frames, n, len(columns)))
        fraction[:, :, 0] = 0.02
        fraction[:, :, 1] = 0.015
        fraction[:, :, 2] = 0.005
        f["fraction"] = fraction[:-1] if cut_last_fraction else fraction


def test_reads_a_layer_file(tmp_path):
    write_layer_file(tmp_path / "a.h5")
    layers = read_layers(tmp_path / "a.h5")
    assert layers.columns == ["total", "class_0", "class_1"]
    assert layers.fraction.shape == (3, 10, 3)
    assert layers.step.tolist() == [0, 50, 100]
    np.testing.assert_allclose(layers.solid_volume(), 0.02 * 10 * 1e-3 * 1e-6)
    assert layers.attributes["particle_density"] == 2650.0
    np.testing.assert_allclose(layers.column("class_0"), 0.015)
    with pytest.raises(KeyError, match="no column 'class_9'"):
        layers.column("class_9")


def test_frame_cut_short_by_a_killed_run_is_left_out(tmp_path):
    write_layer_file(tmp_path / "killed.h5", cut_last_fraction=True)
    layers = read_layers(tmp_path / "killed.h5")
    assert len(layers.time) == len(layers.step) == len(layers.fraction) == 2


@pytest.mark.parametrize("kwargs, message", [
    ({"version": 2}, "layer schema version 2; this reader understands version 1"),
    ({"schema": "sedimemt-layers"}, "damaged: it holds a layer file's datasets, but its schema attribute reads "
     "'sedimemt-layers'"),
])
def test_other_schemas_are_refused(tmp_path, kwargs, message):
    write_layer_file(tmp_path / "other.h5", **kwargs)
    with pytest.raises(LayerFileError, match=message):
        read_layers(tmp_path / "other.h5")


def test_a_foreign_hdf5_file_is_not_a_layer_file(tmp_path):
    with h5py.File(tmp_path / "foreign.h5", "w") as f:
        f.attrs["schema"] = "someone-elses"
        f["data"] = np.arange(3.0)
    with pytest.raises(LayerFileError, match="not a SEDIMENT layer file"):
        read_layers(tmp_path / "foreign.h5")


def _changed(path: Path, change) -> Path:
    write_layer_file(path)
    with h5py.File(path, "r+") as f:
        change(f)
    return path


@pytest.mark.parametrize("change, message", [
    (lambda f: f["fraction"].__setitem__(slice(None), 0.0), "its first frame holds no solids"),
    (lambda f: f.attrs.__setitem__("particle_density", 500.0), "its particle_density is 500 kg/m3, which no particle "
     "density is"),
    (lambda f: f.attrs.__setitem__("fluid_viscosity", 1e6), "its fluid_viscosity is 1e+06 Pa s"),
    (lambda f: f.attrs.__setitem__("fluid_density", 3000.0), "not denser than its fluid"),
    (lambda f: f.attrs.__setitem__("columns", "tota,class_0,class_1"), "its columns attribute reads 'tota,class_0"),
    (lambda f: f.attrs.__setitem__("columns", "total,class_0,total"), "its columns attribute reads"),
    (lambda f: f.attrs.__setitem__("units", "furlongs"), "units 'furlongs'"),
    (lambda f: f.attrs.__setitem__("layer_thickness", 2e-3), "are not those of its layer_centre dataset"),
    (lambda f: f["fraction"].__setitem__((1, 4, 2), 0.5), "do not add up to the total in frame 1"),
    (lambda f: f["step"].__setitem__(2, 10), "do not run forward"),
])
def test_a_layer_file_is_judged_by_its_content(tmp_path, change, message):
    """Wherever the file lies (no run record beside it), content no run writes is refused by name."""
    path = _changed(tmp_path / "copied.h5", change)
    with pytest.raises(LayerFileError, match=message.replace("(", r"\(").replace("+", r"\+")) as refused:
        read_layers(path)
    assert "damaged, or not written by fix layers/hdf5" in str(refused.value)


def test_truncated_and_foreign_files_give_clear_errors(tmp_path):
    write_layer_file(tmp_path / "good.h5", frames=50)
    data = (tmp_path / "good.h5").read_bytes()
    (tmp_path / "truncated.h5").write_bytes(data[: len(data) // 3])
    with pytest.raises(LayerFileError, match="truncated or corrupt"):
        read_layers(tmp_path / "truncated.h5")
    (tmp_path / "notes.h5").write_text("not hdf5\n")
    with pytest.raises(LayerFileError, match="not a readable HDF5 file"):
        read_layers(tmp_path / "notes.h5")
    with pytest.raises(LayerFileError, match="no such layer file"):
        read_layers(tmp_path / "missing.h5")


def test_the_fluid_of_each_frame_is_read_and_checked(tmp_path):
    """The per-frame fluid (a deck that re-issues the water): read as written; a frame without it is
    damage."""
    def with_fluid(name: str, fluid, complete: int) -> Path:
        path = tmp_path / name
        write_layer_file(path)
        with h5py.File(path, "r+") as f:
            f["fluid"] = np.asarray(fluid, float)
            f.attrs["complete"] = complete
        return path
    water = [[998.2, 1.002e-3], [997.0, 0.89e-3], [996.0, 0.80e-3]]
    layers = read_layers(with_fluid("whole.h5", water, 1))
    np.testing.assert_array_equal(layers.fluid, water)
    for complete in (1, 0):
        with pytest.raises(LayerFileError, match="not a density and a viscosity > 0 per frame"):
            read_layers(with_fluid(f"damaged{complete}.h5", water[:2] + [[0.0, 0.0]], complete))


def test_frames_past_those_written_whole_are_not_read(tmp_path):
    """A run killed (or a disk filled) while it wrote a frame leaves its datasets one frame longer than the
    count its writer sets once the frame is flushed (attribute `frames`), that frame torn: HDF5's fill value
    (0) in some datasets, as clone 60's killed run left it. The counted frames are read; without a count
    (a file of an earlier version) the torn frame is refused, not read."""
    path = tmp_path / "torn.h5"
    write_layer_file(path)
    with h5py.File(path, "r+") as f:
        whole = len(f["time"])
        f["fluid"] = np.tile([998.2, 1.002e-3], (whole, 1))
        for name in ("time", "step", "fraction", "fluid"):
            data = f[name][:]
            del f[name]
            f[name] = np.concatenate([data, np.zeros((1,) + data.shape[1:], data.dtype)])
    with pytest.raises(LayerFileError, match="frame times are not increasing"):
        read_layers(path)
    with h5py.File(path, "r+") as f:
        f.attrs["frames"] = float(whole)
    layers = read_layers(path)
    assert len(layers.time) == whole and np.all(np.diff(layers.time) > 0)
