"""The bench shell scripts' --help: their usage, never an argument (bench_workers.sh
ran "--help" as the evlife binary; build_cost.sh emptied a build dir named "--help")."""
import os
import subprocess

import pytest

BENCH = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


@pytest.mark.parametrize("script", ["bench_process.sh", "bench_startup.sh", "bench_workers.sh", "build_cost.sh"])
@pytest.mark.parametrize("flag", ["--help", "-h"])
def test_help_prints_the_usage_and_touches_nothing(script, flag, tmp_path):
    r = subprocess.run(["sh", os.path.join(BENCH, script), flag], cwd=tmp_path, capture_output=True, text=True,
                       timeout=30)
    assert r.returncode == 0, r.stderr
    assert "bench/" + script in r.stdout  # the usage line names the script
    assert not r.stdout.startswith("#!") and "\n#" not in r.stdout  # the comment, without its markers
    assert r.stderr == ""
    assert os.listdir(tmp_path) == []
