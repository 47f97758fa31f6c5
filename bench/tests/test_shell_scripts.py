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


def run_script(script, args, tmp_path):
    return subprocess.run(["sh", os.path.join(BENCH, script), *args], cwd=tmp_path, capture_output=True, text=True,
                          timeout=60)


# A binary that is missing or fails, zero runs: exit non-zero, named, before any
# figure (bench_startup.sh printed "evlife --help:  ms" and exit 0; zero runs
# printed a report of blanks and sed errors).
@pytest.mark.parametrize("script", ["bench_process.sh", "bench_startup.sh", "bench_workers.sh"])
def test_a_missing_binary_is_named_before_any_figure(script, tmp_path):
    r = run_script(script, [str(tmp_path / "absent")], tmp_path)
    assert r.returncode == 2, r.stdout
    assert "absent: not an executable file" in r.stderr
    assert r.stdout == ""


def test_a_failing_binary_is_no_figure(tmp_path):
    r = run_script("bench_startup.sh", ["/bin/false"], tmp_path)
    assert r.returncode == 1, r.stdout
    assert "'/bin/false --help' failed" in r.stderr
    assert " ms" not in r.stdout


@pytest.mark.parametrize("script", ["bench_process.sh", "bench_workers.sh"])
@pytest.mark.parametrize("runs", ["0", "two"])
def test_runs_must_be_a_whole_number(script, runs, tmp_path):
    r = run_script(script, ["/bin/true", runs], tmp_path)
    assert r.returncode == 2, r.stdout
    assert f"runs must be a whole number, at least 1 (got '{runs}')" in r.stderr
    assert r.stdout == ""
