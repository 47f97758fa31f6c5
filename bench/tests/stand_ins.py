"""What the figure scripts' tests share: the script loaded as a module (with
bench/ on the path, for its own modules) and a stand-in for accuracy_sweep."""
import importlib.util
import os
import stat
import sys

BENCH = os.path.join(os.path.dirname(__file__), os.pardir)
sys.path.insert(0, BENCH)  # the scripts' own modules (sweep_table, plotting)


def script_path(name):
    return os.path.join(BENCH, name + ".py")


def load_script(name):
    spec = importlib.util.spec_from_file_location(name, script_path(name))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def sweep_stand_in(tmp_path, body):
    """An executable `accuracy_sweep` in tmp_path that runs `body` (Python)."""
    path = tmp_path / "accuracy_sweep"
    path.write_text(f"#!{sys.executable}\n" + body)
    path.chmod(path.stat().st_mode | stat.S_IEXEC)
    return str(path)
