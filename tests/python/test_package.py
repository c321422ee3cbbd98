"""The package itself: version, typing files, documentation, and an import that does not pull in SciPy."""
import inspect
import subprocess
import sys
from pathlib import Path

import kdm


def test_version_is_the_librarys(cli):
    assert kdm.__version__ == kdm._kdm.__version__
    import os
    done = subprocess.run([os.environ["KDM_CLI"], "--version"], capture_output=True, text=True)
    assert kdm.__version__ in done.stdout + done.stderr
    assert all(part.isdigit() for part in kdm.__version__.split("."))


def test_typing_files_ship_with_the_package():
    folder = Path(kdm.__file__).parent
    assert (folder / "py.typed").exists()
    stub = (folder / "__init__.pyi").read_text()
    for name in kdm.__all__:
        if name != "__version__":
            assert f"def {name}(" in stub or f"class {name}" in stub, name


def test_every_public_name_is_documented():
    for name in kdm.__all__:
        obj = getattr(kdm, name)
        if name != "__version__":
            assert inspect.getdoc(obj) and len(inspect.getdoc(obj)) > 40, name
    for method in ("builtin", "load", "save", "query", "thresholds", "stable_positions"):
        assert inspect.getdoc(getattr(kdm.Tileset, method)), method
    assert "row 0 at the TOP" in inspect.getdoc(kdm.sample)


def test_import_does_not_load_scipy():
    code = "import sys, kdm; kdm.sample(16); print('scipy' in sys.modules)"
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "False"


def test_dir_lists_every_public_name_without_loading_it():
    # A fresh interpreter: BlueNoise is loaded on first use, and dir() lists it before that.
    code = ("import sys, kdm; names = dir(kdm); "
            "print(sorted(set(kdm.__all__) - set(names)), 'kdm._engine' in sys.modules, 'scipy' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    assert done.stdout.strip() == "[] False False"
    assert "BlueNoise" in dir(kdm) and "sample" in dir(kdm) and "_kdm" in dir(kdm)


def test_the_example_runs(tmp_path):
    from conftest import SOURCE_DIR
    done = subprocess.run([sys.executable, str(SOURCE_DIR / "examples" / "python_example.py"), str(tmp_path)],
                          capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert "stipple:" in done.stdout and (tmp_path / "sphere-dots.png").exists()
