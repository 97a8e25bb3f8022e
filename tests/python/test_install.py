# SPDX-License-Identifier: GPL-2.0-or-later
"""`pip install .` in a virtual environment: the package, its console script and a `_core` that
links no LAMMPS (Debian's build backend; no network, so no build isolation). The notebooks run with
the installed package too (test_notebooks.py)."""
import os
import re
import shutil
import subprocess
from pathlib import Path

REPO = Path(__file__).resolve().parents[2]


def test_pip_install_gives_the_package_and_the_command(installed, tmp_path):
    venv = installed    # the README's command, as written (conftest.py)
    out = subprocess.run([venv / "bin" / "sediment", "terminal", "--diameter", "1e-4", "--particle-density", "2700",
                          "--fluid-density", "1000", "--viscosity", "1e-3"], capture_output=True, text=True,
                         check=True, cwd=tmp_path).stdout
    assert "terminal velocity: 0.009265 m/s (moving)" in out
    where = subprocess.run([venv / "bin" / "python", "-c", "import sediment._core as c; print(c.__file__)"],
                           capture_output=True, text=True, check=True, cwd=tmp_path).stdout.strip()
    assert where.startswith(str(venv))
    linked = subprocess.run(["ldd", where], capture_output=True, text=True, check=True).stdout
    assert "lammps" not in linked and "sediment_lammps" not in linked
    # the release the metadata, the command and the module state: the header's (setup.py reads it)
    release = re.search(r'version = "([0-9.]+)"',
                        (REPO / "core" / "include" / "sediment" / "version.hpp").read_text()).group(1)
    stated = subprocess.run([venv / "bin" / "python", "-c", "from importlib.metadata import version; import sediment; "
                             "print(version('sediment'), sediment.__version__)"], capture_output=True, text=True,
                            check=True, cwd=tmp_path).stdout.split()
    command = subprocess.run([venv / "bin" / "sediment", "--version"], capture_output=True, text=True, check=True)
    assert stated == [release, release] and command.stdout == f"sediment {release}\n"
    # the main job with the installed package, LAMMPS from the build
    env = dict(os.environ, SEDIMENT_LMP=str(REPO / "build" / "lmp_sediment"), PYTHONPATH="")
    sediment = venv / "bin" / "sediment"
    for args in (["sample", REPO / "examples" / "granulometry" / "psd" / "sample5.csv", "--out", "s", "--particles",
                  "2000", "--t-end", "7200"], ["run", "s/in.sedimentation", "--quiet"],
                 ["readout", "s/layers.h5", "--out", "s/readout"]):
        done = subprocess.run([sediment, *map(str, args)], capture_output=True, text=True, cwd=tmp_path, env=env)
        assert done.returncode == 0, done.stderr
    assert (tmp_path / "s" / "readout" / "granulometry.png").is_file()
    assert list((venv / "lib").glob("python3*/site-packages/sediment/py.typed"))


def test_the_plugin_builds_alone_against_the_headers(tmp_path):
    """The README's plugin command: LAMMPS's headers only, no liblammps; a library that does not
    exist is refused at configure."""
    headers = REPO / "build" / "lammps-headers"
    command = next(line.strip() for line in (REPO / "README.md").read_text().splitlines()
                   if "SEDIMENT_PLUGIN_ONLY=ON" in line and line.strip().startswith("cmake"))
    # Built in a folder of build/, at the same depth in every clone, so that ccache serves what an
    # earlier clone compiled (paths are hashed relative to the checkout: CMakeLists.txt)
    folder = REPO / "build" / "test-plugin-only"
    shutil.rmtree(folder, ignore_errors=True)
    command = command.replace("/path/to/lammps/src", str(headers)).replace("build-plugin", str(folder))
    # Without link-time optimisation, whose link takes a minute of CPU here: make build's plugin is
    # built with the same CMake function and optimised, and make test-lammps-2022 loads that one
    command = command.replace("-DSEDIMENT_PLUGIN_ONLY=ON", "-DSEDIMENT_PLUGIN_ONLY=ON -DSEDIMENT_LTO=OFF", 1)
    subprocess.run(["bash", "-c", command], check=True, cwd=REPO, capture_output=True)
    plugin = folder / "sedimentplugin.so"
    assert plugin.is_file() and not list(folder.glob("lmp_sediment"))
    assert "lammps" not in subprocess.run(["ldd", plugin], capture_output=True, text=True, check=True).stdout
    refused = subprocess.run(["cmake", "-S", REPO, "-B", tmp_path / "lib", f"-DLAMMPS_SOURCE_DIR={headers}",
                              "-DLAMMPS_LIBRARY=/nowhere/liblammps.so"], capture_output=True, text=True)
    assert refused.returncode != 0 and "LAMMPS_LIBRARY=/nowhere/liblammps.so does not exist" in refused.stderr


def test_the_in_tree_install_on_debian_12s_lammps_checks_first_and_lists_the_package(tmp_path):
    """install-in-tree.sh on the LAMMPS source that `make build` fetched (Debian 12's, 6 Jan 2022):
    LAMMPS's own check-packages.py and check-styles.py find the package and every style; a second
    run changes nothing; a tree that lacks a place changes in nothing."""
    import tarfile

    # The source package make build fetched for the headers (once per machine), fetched here if a build
    # older than that cache left it elsewhere
    downloads = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "sediment" / "lammps-source-bookworm"
    version = subprocess.run(["dpkg-query", "-W", "-f=${source:Version}", "liblammps-dev"], capture_output=True,
                             text=True, check=True).stdout
    tarball = Path(subprocess.run([REPO / "scripts" / "fetch-lammps-source.sh", "bookworm", version, downloads],
                                  capture_output=True, text=True, check=True).stdout.split()[0])
    with tarfile.open(tarball) as archive:
        members = [m for m in archive.getmembers() if "/cmake/" in m.name or "/doc/" in m.name
                   or m.name.endswith("/src/lammps.h") or m.name.endswith("/src/GRANULAR/fix_wall_gran.h")]
        archive.extractall(tmp_path, members)
    tree = next(tmp_path.iterdir())
    install = REPO / "lammps-pkg" / "install-in-tree.sh"
    subprocess.run([install, tree], check=True, capture_output=True)

    def check(script: str) -> str:
        return subprocess.run(["/usr/bin/python3", tree / "doc" / "utils" / script, "-s", tree / "src", "-d",
                               tree / "doc" / "src"], capture_output=True, text=True, check=True).stdout
    assert "missing" not in check("check-packages.py") and "Found 2 packages" in check("check-packages.py")
    styles = check("check-styles.py")
    assert "missing" not in styles.lower() and "incomplete" not in styles.lower()

    def files(root: Path) -> dict[str, bytes]:
        return {str(p.relative_to(root)): p.read_bytes() for p in sorted(root.rglob("*")) if p.is_file()}
    before = files(tree)
    subprocess.run([install, tree], check=True, capture_output=True)
    assert files(tree) == before
    broken = tmp_path / "broken"
    shutil.copytree(tree, broken)
    shutil.rmtree(broken / "src" / "SEDIMENT")
    (broken / "doc" / "src" / "Packages_details.rst").unlink()
    before = files(broken)
    refused = subprocess.run([install, broken], capture_output=True, text=True)
    assert refused.returncode == 1 and "nothing was changed" in refused.stderr and "Packages_details.rst" in refused.stderr
    assert files(broken) == before


def test_the_example_readme_commands_run_in_sequence(tmp_path):
    """lammps-pkg/examples/README's serial and 2-rank commands, one after the other in one folder
    (lmp_sediment standing for an lmp built with the package)."""
    lmp = os.environ["SEDIMENT_LMP"]
    shutil.copy(REPO / "lammps-pkg" / "examples" / "in.settling", tmp_path)
    commands = [line.split("(")[0].split() for line in (REPO / "lammps-pkg" / "examples" / "README").read_text().splitlines()
                if line.strip().startswith(("lmp ", "mpirun "))]
    assert len(commands) == 2
    env = dict(os.environ, OMPI_ALLOW_RUN_AS_ROOT="1", OMPI_ALLOW_RUN_AS_ROOT_CONFIRM="1")
    for words in commands:
        words = [lmp if w == "lmp" else w for w in words]
        if words[0] == "mpirun":
            words[1:1] = ["--oversubscribe"]
        done = subprocess.run(words + ["-log", "none"], cwd=tmp_path, capture_output=True, text=True, env=env)
        assert done.returncode == 0 and "ERROR" not in done.stdout, done.stdout[-800:]
    assert (tmp_path / "layers.h5").is_file() and (tmp_path / "layers.np2.h5").is_file()
