// `evlife devices` and `evlife run --source dvs128[:SERIAL]` as a user runs
// them, against the emulated camera: the CLI child process inherits the
// umockdev environment (LD_PRELOAD + UMOCKDEV_DIR) and talks to this test's
// usbdevfs emulation. Runs under umockdev-wrapper.
#include <gtest/gtest.h>

#include <sys/wait.h>

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "dvs128_emulator.h"
#include "evlife/io/augmented_event_reader.h"

namespace {

using evlife::testing::dvs128_word;
using evlife::testing::kResetWord;
using evlife::testing::kWrapWord;
using evlife::testing::UsbTestbed;
using evlife::testing::words_to_bytes;

struct CliResult {
  int exit_code = -1;
  std::string out;
  std::string err;
};

std::string slurp(const std::string& path) {
  std::ifstream f(path);
  std::stringstream s;
  s << f.rdbuf();
  return s.str();
}

CliResult run_cli(const std::string& args, const std::string& tag) {
  const std::string base = std::string(EVLIFE_BINARY_DIR) + "/test_dvs128_cli_" + tag;
  const std::string cmd = std::string(EVLIFE_CLI_PATH) + " " + args + " >" + base + ".out 2>" +
                          base + ".err";
  const int status = std::system(cmd.c_str());
  CliResult r;
  r.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
  r.out = slurp(base + ".out");
  r.err = slurp(base + ".err");
  std::remove((base + ".out").c_str());
  std::remove((base + ".err").c_str());
  return r;
}

TEST(Dvs128Cli, DevicesListsTheCameraWithItsSourceSpec) {
  UsbTestbed bed;
  bed.add_dvs128("SN-7", 14, 1, 5);
  const auto r = run_cli("devices", "devices");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.out.find("dvs128:SN-7"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("bus 1 device 5"), std::string::npos) << r.out;
}

TEST(Dvs128Cli, DevicesWithoutCameraSaysWhatToCheck) {
  UsbTestbed bed;
  bed.add_other_device(0x1d6b, 0x0002, 1, 1);
  const auto r = run_cli("devices", "none");
  EXPECT_EQ(r.exit_code, 3);
  EXPECT_NE(r.err.find("no event camera"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("1d6b:0002"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("99-evlife-dvs128.rules"), std::string::npos) << r.err;
}

// A camera listed with a problem (here it does not answer: its serial number
// stalls) is not usable: exit 3 and what to check, as with none (exit 0 and
// the problem on its line before, while the README promised exit 3).
TEST(Dvs128Cli, DevicesWithOnlyAnUnusableCameraSaysWhatToCheck) {
  UsbTestbed bed;
  bed.add_dvs128("SN-7", 14, 1, 5).set_strings_stall(true);
  const auto r = run_cli("devices", "unusable");
  EXPECT_EQ(r.exit_code, 3) << r.out << r.err;
  EXPECT_NE(r.out.find("bus 1 device 5"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("-- cannot read the serial number"), std::string::npos) << r.out;
  EXPECT_NE(r.err.find("no usable event camera"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("99-evlife-dvs128.rules"), std::string::npos) << r.err;
}

TEST(Dvs128Cli, RunFromTheCameraWritesEverythingReadThenReportsTheUnplug) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128("SN-9");
  std::vector<std::uint32_t> words = {kResetWord};
  std::vector<std::int64_t> truth_t;
  for (int i = 0; i < 3000; ++i) {
    const int t = 10 * i;
    if (i > 0 && t / 0x4000 != (t - 10) / 0x4000) words.push_back(kWrapWord);
    words.push_back(dvs128_word(i % 128, (i / 7) % 128, i % 3 == 0, t % 0x4000));
    truth_t.push_back(t);
  }
  const auto bytes = words_to_bytes(words);
  for (std::size_t at = 0; at < bytes.size(); at += 4096) {
    cam.push_packet({bytes.begin() + static_cast<long>(at),
                     bytes.begin() + static_cast<long>(std::min(bytes.size(), at + 4096))});
  }
  const std::string out_path = std::string(EVLIFE_BINARY_DIR) + "/test_dvs128_cli_run.csv";
  CliResult r;
  std::thread cli([&] { r = run_cli("run --source dvs128:SN-9 --quiet -o " + out_path, "run"); });
  EXPECT_TRUE(cam.wait_for([&] { return cam.queued_packets() == 0; }, std::chrono::seconds(10)));
  cam.unplug();
  cli.join();
  EXPECT_EQ(r.exit_code, 3) << r.err;
  EXPECT_NE(r.err.find("vanished"), std::string::npos) << r.err;
  auto reader = evlife::io::open_augmented_reader(out_path);
  std::vector<evlife::AugmentedEvent> got(truth_t.size() + 10);
  std::size_t n = 0;
  while (const std::size_t k = reader->read(std::span(got).subspan(n))) n += k;
  ASSERT_EQ(n, truth_t.size());
  for (std::size_t i = 0; i < n; ++i) ASSERT_EQ(got[i].event.t_us, truth_t[i]) << i;
  std::remove(out_path.c_str());
}

// A timestamp wrap word lost on the way: the words after it read as earlier
// than the event before them, and the decoder stamps them with its time. The
// run says how many, in its summary and (whatever -q says) on stderr; before,
// the counter was kept and never shown.
TEST(Dvs128Cli, EventsStampedWithAnEarlierEventsTimeAreCountedAndShown) {
  std::vector<std::uint32_t> words = {kResetWord, dvs128_word(5, 5, true, 16000), dvs128_word(6, 5, true, 16300)};
  for (int i = 0; i < 4; ++i) words.push_back(dvs128_word(7 + i, 5, true, 10 * (i + 1)));  // the wrap word lost
  const std::string out_path = std::string(EVLIFE_BINARY_DIR) + "/test_dvs128_cli_regressions.bin";
  for (const bool quiet : {false, true}) {
    UsbTestbed bed;
    auto& cam = bed.add_dvs128("SN-4");
    cam.push_packet(words_to_bytes(words));
    CliResult r;
    std::thread cli([&] {
      r = run_cli(std::string("run --source dvs128:SN-4 ") + (quiet ? "--quiet " : "") + "-o " + out_path,
                  quiet ? "regressions_q" : "regressions");
    });
    EXPECT_TRUE(cam.wait_for([&] { return cam.queued_packets() == 0; }, std::chrono::seconds(10)));
    cam.unplug();
    cli.join();
    EXPECT_EQ(r.exit_code, 3) << r.err;
    EXPECT_NE(r.err.find("warning: 4 events of"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("were stamped with its time"), std::string::npos) << r.err;
    if (!quiet) {
      EXPECT_NE(r.out.find("camera : 7 words: 6 events, 0 special (sync), 0 timestamp wraps, 1 resets; 4 stamped"),
                std::string::npos) << r.out;
    }
  }
  std::remove(out_path.c_str());
}

// A --biases file that cannot be read, or holds a bad line, is a setting
// refused: exit 2 (as a bad --config), the file and line named, no request
// sent to the camera. It was exit 3, "input error", as if the camera's
// events were bad. An empty name is a usage error (it read as no file).
TEST(Dvs128Cli, ABadBiasFileIsASettingRefusedBeforeTheCameraOpens) {
  UsbTestbed bed;
  auto& cam = bed.add_dvs128("SN-7");
  const std::string dir = std::string(EVLIFE_BINARY_DIR);
  const std::string bad = dir + "/test_dvs128_cli_bad_biases.yaml";
  {
    std::ofstream f(bad);
    f << "cas: 5\nrefr: -1\n";
  }
  const std::string out_path = dir + "/test_dvs128_cli_biases.csv";
  const struct {
    std::string file, said;
  } cases[] = {{dir + "/no_such_biases.yaml", dir + "/no_such_biases.yaml: cannot open the DVS128 bias file"},
               {bad, bad + ":2: bias 'refr' must be an integer"}};
  for (const auto& c : cases) {
    const auto r = run_cli("run --source dvs128:SN-7 --biases " + c.file + " --quiet -o " + out_path, "biases");
    EXPECT_EQ(r.exit_code, 2) << r.err;
    EXPECT_NE(r.err.find("configuration error: " + c.said), std::string::npos) << r.err;
  }
  const auto empty = run_cli("run --source dvs128:SN-7 --biases '' --quiet -o " + out_path, "biases");
  EXPECT_EQ(empty.exit_code, 2) << empty.err;
  EXPECT_NE(empty.err.find("--biases needs a file"), std::string::npos) << empty.err;
  EXPECT_TRUE(cam.vendor_requests().empty());
  std::remove(bad.c_str());
}

}  // namespace
