// `evlife run --window`: frames in an on-screen window where a display
// exists, a clear error (never a toolkit abort) where none does. The display
// is Xvfb's in CI (.ci/debian-packages); without xvfb-run that test skips.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "cli_runner.h"

namespace {
const std::filesystem::path kLog = std::filesystem::temp_directory_path() / "evlife_test_run_window.log";
const std::string kRun = std::string("'") + EVLIFE_CLI_PATH +
                         "' run --source synth:edges --sensor 96x96 --duration 0.2 --window";

bool have_xvfb() { return std::system("command -v xvfb-run >/dev/null 2>&1") == 0; }
}  // namespace

TEST(RunWindow, WithoutADisplayTheErrorNamesItAndNothingAborts) {
  const auto r = evlife::test::run_cli("env", "-u DISPLAY -u WAYLAND_DISPLAY " + kRun, kLog);
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("DISPLAY"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("--frames"), std::string::npos) << "the error suggests another output";
}

TEST(RunWindow, AnUnreachableDisplayIsAClearErrorNotACrash) {
  // The GUI toolkit would abort the whole process here; the probe runs it in
  // a child first.
  const auto r = evlife::test::run_cli("env", "-u WAYLAND_DISPLAY DISPLAY=:93 " + kRun, kLog);
  EXPECT_EQ(r.exit_code, 4) << r.output;
  EXPECT_NE(r.output.find("DISPLAY=:93"), std::string::npos) << r.output;
}

TEST(RunWindow, ShowsTheEventClockFramesOnAVirtualDisplay) {
  if (!have_xvfb()) GTEST_SKIP() << "xvfb-run not installed (.ci/debian-packages has it)";
  const auto r = evlife::test::run_cli("xvfb-run", "-a " + kRun + " --render-fps 50", kLog);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The 0.2 s scene's events end before 200 ms (its events are in [0, 0.2 s)):
  // at 50 frames per event-clock second 0, 20, ..., 180 ms.
  EXPECT_NE(r.output.find("frames : 10 shown in a window"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(": ok"), std::string::npos) << "in = out + dropped: " << r.output;
}
