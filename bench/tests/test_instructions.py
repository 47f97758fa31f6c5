"""bench/instructions.py's reading of callgrind_annotate listings (valgrind itself is not needed)."""
import importlib.util
import os

import pytest

SCRIPT = os.path.join(os.path.dirname(__file__), os.pardir, "instructions.py")
spec = importlib.util.spec_from_file_location("instructions", SCRIPT)
instructions = importlib.util.module_from_spec(spec)
spec.loader.exec_module(instructions)

# As callgrind_annotate 3.19 prints them (--inclusive=yes), shortened.
LISTING = """\
--------------------------------------------------------------------------------
Ir
--------------------------------------------------------------------------------
707,579,048 (100.0%)  PROGRAM TOTALS

--------------------------------------------------------------------------------
Ir                    file:function
--------------------------------------------------------------------------------
534,820,763 (75.58%)  ???:evlife::LifetimeEstimator::process(std::span<evlife::Event const, 18446744073709551615ul>, std::span<evlife::AugmentedEvent, 18446744073709551615ul>) [/tmp/b/bench_estimator]
102,909,219 (10.58%)  ???:evlife::detail::(anonymous namespace)::draws(evlife::detail::WindowSamples const&, evlife::detail::EventRng&, int, int const*, float, float, evlife::detail::PlaneCandidate) [clone .avx2] [/tmp/b/bench_estimator]
 58,034,570 ( 8.20%)  /work/main/algo/src/lifetime_estimator.cpp:evlife::LifetimeEstimator::continues_an_edge(int, int, int, long, double, evlife::LifetimeEstimator::EdgePrior&) const [/tmp/b/bench_estimator]
 22,290,781 ( 2.29%)  ./elf/./elf/dl-lookup.c:do_lookup_x [/usr/lib/x86_64-linux-gnu/ld-linux-x86-64.so.2]
"""


def test_counts_and_names_are_read_from_a_listing():
    rows = instructions.annotate_counts(LISTING)
    assert [c for c, _ in rows] == [534820763, 102909219, 58034570, 22290781]  # the totals line left out
    assert instructions.entry_instructions(rows) == 534820763
    names = [instructions.function_name(loc) for _, loc in rows]
    assert names == ["LifetimeEstimator::process", "draws [clone .avx2]", "LifetimeEstimator::continues_an_edge",
                     "do_lookup_x"]


def test_a_profile_without_the_estimator_is_an_error():
    with pytest.raises(ValueError, match="not a bench_estimator build"):
        instructions.entry_instructions(instructions.annotate_counts(LISTING.replace("LifetimeEstimator::process", "x")))


def test_a_missing_binary_is_named(tmp_path):
    missing = str(tmp_path / "bench_estimator")
    with pytest.raises(SystemExit, match="bench_estimator: not an executable file"):
        instructions.main([missing])


def test_a_filter_that_matches_nothing_is_named_without_a_traceback(tmp_path):
    binary = tmp_path / "bench_estimator"
    binary.write_text("#!/bin/sh\nexit 0\n")  # lists no benchmark
    binary.chmod(0o755)
    with pytest.raises(SystemExit, match="no benchmark matches --filter 'NOPE'"):
        instructions.main(["--filter", "NOPE", str(binary)])
