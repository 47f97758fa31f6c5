// evlife::config: the shipped YAML equals the struct defaults, unknown keys
// and out-of-range values are errors naming the key, file and line, --set
// overrides take effect.
#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include "config_presets.h"
#include "evlife/config/config.h"
#include "evlife/config/config_key.h"
#include "evlife/algo/parse_text.h"

namespace {

using evlife::for_each_lifetime_option;
using evlife::LifetimeOptions;
using evlife::OptionInfo;
using evlife::config::Config;
using evlife::config::ConfigBuilder;
using evlife::config::ConfigError;

const std::string kShippedYaml = std::string(EVLIFE_SOURCE_DIR) + "/config/evlife.yaml";

// Writes `text` to a fresh file in the test temp dir and returns its path.
std::string write_temp(const std::string& name, const std::string& text) {
  const auto dir = std::filesystem::path(testing::TempDir()) / "evlife_test_config";
  std::filesystem::create_directories(dir);
  const auto path = dir / name;
  std::ofstream(path) << text;
  return path.string();
}

// Returns the ConfigError message of `fn`, or fails.
template <typename Fn>
std::string error_of(Fn fn) {
  try {
    fn();
  } catch (const ConfigError& e) {
    return e.what();
  }
  ADD_FAILURE() << "expected a ConfigError";
  return {};
}

// Every estimator key of the table: the shipped file states the defaults.
TEST(Config, ShippedYamlStatesEveryEstimatorDefault) {
  ConfigBuilder b;
  b.load_file(kShippedYaml);
  const Config c = b.build();
  const LifetimeOptions d;
  for_each_lifetime_option([&](const OptionInfo& info, auto access) {
    if (info.key.starts_with("sensor.")) return;  // stated by the data, not the file
    EXPECT_EQ(access(c.estimator), access(d)) << info.key;
  });
}

// A preset in config/: valid, and it changes only what it says (`expected`:
// the defaults with its keys set).
void expect_preset(const std::string& file, const LifetimeOptions& expected) {
  ConfigBuilder b;
  b.load_file(std::string(EVLIFE_SOURCE_DIR) + "/config/" + file);
  const Config c = b.build();
  for_each_lifetime_option([&](const OptionInfo& info, auto access) {
    EXPECT_EQ(access(c.estimator), access(expected)) << file << ": " << info.key;
  });
}

TEST(Config, DimLightPresetSetsTheStandardErrorCheck) {
  expect_preset("dim-light.yaml", evlife::test::dim_light_preset());
}

TEST(Config, FaintTexturePresetWidensTheBandWithTheOffsetCheck) {
  expect_preset("faint-texture.yaml", evlife::test::faint_texture_preset());
}

TEST(Config, ShippedYamlEqualsStructDefaults) {
  ConfigBuilder b;
  b.load_file(kShippedYaml);
  const Config c = b.build();
  const LifetimeOptions d;  // the compiled-in defaults
  EXPECT_EQ(c.estimator.sensor, d.sensor);
  EXPECT_EQ(c.estimator.window_size, d.window_size);
  EXPECT_EQ(c.estimator.outlier_fraction, d.outlier_fraction);
  EXPECT_EQ(c.estimator.ransac_confidence, d.ransac_confidence);
  EXPECT_EQ(c.estimator.inlier_tolerance_us, d.inlier_tolerance_us);
  EXPECT_EQ(c.estimator.inlier_tolerance_lifetime_fraction, d.inlier_tolerance_lifetime_fraction);
  EXPECT_EQ(c.estimator.regularization, d.regularization);
  EXPECT_EQ(c.estimator.lambda_offset, d.lambda_offset);
  EXPECT_EQ(c.estimator.lambda_gain, d.lambda_gain);
  EXPECT_EQ(c.estimator.lambda_decay_per_us, d.lambda_decay_per_us);
  EXPECT_EQ(c.estimator.lambda_unit_px2, d.lambda_unit_px2);
  EXPECT_EQ(c.estimator.max_lifetime_us, d.max_lifetime_us);
  EXPECT_EQ(c.estimator.seed, d.seed);
}

TEST(Config, ShippedYamlListsEveryKeyWithItsDefault) {
  // Covers sections added later too: every key of the schema must appear in
  // the documented file with the struct's default value.
  ConfigBuilder b;
  b.load_file(kShippedYaml);
  const Config from_file = b.build();
  const Config defaults;
  for (const auto& key : evlife::config::config_keys()) {
    // Keys the input decides are comments there (a stated size would bind every input).
    EXPECT_EQ(b.origin(key.name) != nullptr, !evlife::config::is_taken_from_the_input(key.name))
        << key.name << " in " << kShippedYaml;
    EXPECT_EQ(key.format(from_file), key.format(defaults)) << key.name;
  }
}

// Number of members of an aggregate: the most initializers it accepts.
struct AnyField {
  template <typename T>
  operator T() const;  // NOLINT: converts to any member type (unevaluated only)
};
template <typename T, typename... Fields>
constexpr std::size_t member_count() {
  if constexpr (requires { T{Fields{}..., AnyField{}}; }) {
    return member_count<T, Fields..., AnyField>();
  } else {
    return sizeof...(Fields);
  }
}

TEST(Config, EveryEstimatorFieldHasAKey) {
  // A field added to LifetimeOptions without a key here fails this test.
  std::size_t estimator_keys = 0;
  for (const auto& key : evlife::config::config_keys()) {
    if (key.name.rfind("estimator.", 0) == 0) ++estimator_keys;
  }
  // sensor is one member with two keys (width, height).
  EXPECT_EQ(estimator_keys, member_count<LifetimeOptions>() + 1);
}

TEST(Config, DefaultsValidate) {
  const Config c = ConfigBuilder().build();
  EXPECT_EQ(c.estimator.window_size, LifetimeOptions{}.window_size);
  EXPECT_EQ(evlife::validate_lifetime_options(c.estimator), "");
}

TEST(Config, UnknownKeyNamesKeyFileAndLine) {
  const auto path = write_temp("unknown.yaml",
                               "estimator:\n"
                               "  window_size: 7\n"
                               "  windw_size: 9\n");
  const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
  EXPECT_NE(msg.find("estimator.windw_size"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path + ":3"), std::string::npos) << msg;
  EXPECT_NE(msg.find("did you mean 'estimator.window_size'"), std::string::npos) << msg;
}

TEST(Config, UnknownSectionIsAnError) {
  const auto path = write_temp("section.yaml", "estimatr:\n  window_size: 7\n");
  const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
  EXPECT_NE(msg.find("estimatr"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path + ":1"), std::string::npos) << msg;
}

TEST(Config, UnknownKeyInSetIsAnError) {
  const std::string msg = error_of([] { ConfigBuilder().set("estimator.nope=1"); });
  EXPECT_NE(msg.find("estimator.nope"), std::string::npos) << msg;
}

TEST(Config, OutOfRangeNamesKeyOriginAndRange) {
  const auto path = write_temp("range.yaml",
                               "estimator:\n"
                               "  outlier_fraction: 0.95\n");
  ConfigBuilder b;
  b.load_file(path);  // ranges are checked once, by build()
  const std::string msg = error_of([&] { b.build(); });
  EXPECT_NE(msg.find("estimator.outlier_fraction"), std::string::npos) << msg;
  EXPECT_NE(msg.find("0.95"), std::string::npos) << msg;
  EXPECT_NE(msg.find("(0, 0.9]"), std::string::npos) << msg;
  EXPECT_NE(msg.find(path + ":2"), std::string::npos) << msg;
}

// A configuration from a pipe (`--config <(...)`, /dev/stdin) is read once:
// its later opens found the pipe empty and the defaults stood, silently (an
// out-of-range value too), and a named FIFO made the second open wait.
TEST(Config, AConfigurationFromAPipeIsReadOnceAndApplied) {
  for (const std::string value : {"3", "4"}) {
    int fds[2];
    ASSERT_EQ(::pipe(fds), 0);
    const std::string text = "estimator:\n  window_size: " + value + "\n";
    ASSERT_EQ(::write(fds[1], text.data(), text.size()), static_cast<ssize_t>(text.size()));
    ::close(fds[1]);
    const std::string path = "/proc/self/fd/" + std::to_string(fds[0]);
    ConfigBuilder b;
    b.load_file(path);
    ::close(fds[0]);
    if (value == "3") {
      EXPECT_EQ(b.build().estimator.window_size, 3);
    } else {
      const std::string msg = error_of([&] { b.build(); });
      EXPECT_NE(msg.find("estimator.window_size = 4 (set at " + path + ":2)"), std::string::npos) << msg;
    }
  }
}

TEST(Config, EvenWindowIsOutOfRange) {
  ConfigBuilder b;
  b.set("estimator.window_size=4");
  const std::string msg = error_of([&] { b.build(); });
  EXPECT_NE(msg.find("estimator.window_size"), std::string::npos) << msg;
  EXPECT_NE(msg.find("odd"), std::string::npos) << msg;
  EXPECT_NE(msg.find("--set"), std::string::npos) << msg;
}

TEST(Config, WrongTypeIsAnError) {
  EXPECT_THROW(ConfigBuilder().set("estimator.window_size=5.5"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.window_size=five"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.regularization=maybe"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.inlier_tolerance_us=nan"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.seed=-3"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.window_size"), ConfigError);  // no '='
  // One sign at most ("+-0" was 0, "+-1" -1, in both number parsers).
  EXPECT_THROW(ConfigBuilder().set("estimator.seed=+-0"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("engine.margin_px=+-1"), ConfigError);
  EXPECT_THROW(ConfigBuilder().set("estimator.inlier_tolerance_us=+-0"), ConfigError);
  for (const auto& [text, margin_px] : {std::pair{"+8", 8}, std::pair{"-1", -1}}) {
    ConfigBuilder b;
    b.set(std::string("engine.margin_px=") + text);
    EXPECT_EQ(b.build().engine.margin_px, margin_px) << text;
  }
  EXPECT_EQ(evlife::parse_decimal("+-1"), std::nullopt);
  EXPECT_EQ(evlife::parse_decimal("-+1"), std::nullopt);
  EXPECT_EQ(evlife::parse_decimal("+1.5"), 1.5);
  EXPECT_EQ(evlife::parse_decimal("-1.5"), -1.5);
  EXPECT_EQ(evlife::parse_time_us("+-0s"), std::nullopt);
  const auto path = write_temp("type.yaml", "estimator:\n  window_size: [5, 7]\n");
  const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
  EXPECT_NE(msg.find("estimator.window_size"), std::string::npos) << msg;
}

// A review helper's finding: a whole number beyond its field's type (2^31 + 1
// for an int) was "'2147483649' is not a valid integer", where 100 is "out of range".
TEST(Config, AWholeNumberBeyondItsTypeIsOutOfRangeNotNoInteger) {
  for (const std::string text : {"2147483649", "-2147483653", "99999999999999999999999"}) {
    const std::string msg = error_of([&] { ConfigBuilder().set("estimator.window_size=" + text); });
    EXPECT_NE(msg.find("--set estimator.window_size=" + text + ": estimator.window_size = " + text +
                       " is out of range; allowed: odd, [3, 15]"),
              std::string::npos)
        << msg;
  }
  const std::string negative_seed = error_of([] { ConfigBuilder().set("estimator.seed=-3"); });
  EXPECT_NE(negative_seed.find("estimator.seed = -3 is out of range"), std::string::npos) << negative_seed;
  for (const std::string text : {"five", "5.5", "0x", "+", "1e3", "0xg", "0x80000000"}) {
    const std::string msg = error_of([&] { ConfigBuilder().set("estimator.window_size=" + text); });
    EXPECT_NE(msg.find("estimator.window_size = '" + text + "' is not a valid integer"), std::string::npos) << msg;
  }
}

// An integer key takes decimal digits with one sign at most (not YAML 1.2's
// 0x hex, nor Python's 2_0): `--set engine.workers=0x2` ran 2 workers (hex was read
// for every integer key). Hexadecimal is the seed's alone (a bit pattern, the
// shipped file's `seed: 0x5eed`). Floats: finite decimal numbers, 1e3 too.
TEST(Config, AnIntegerIsDecimalDigitsNotHexNorAFloatsText) {
  for (const std::string text : {"0x2", "0X2", "2.0", "2e0", "2abc", " 2 ", "0b10", "2_0", "0x"}) {
    const std::string msg = error_of([&] { ConfigBuilder().set("engine.workers='" + text + "'"); });
    EXPECT_NE(msg.find("--set engine.workers='" + text + "': engine.workers = '" + text +
                       "' is not a valid integer (decimal digits; allowed: [1, 32])"),
              std::string::npos)
        << msg;
  }
  const auto path = write_temp("hex.yaml", "engine:\n  workers: 0x2\n");
  const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
  EXPECT_NE(msg.find(path + ":2: engine.workers = '0x2' is not a valid integer"), std::string::npos) << msg;
  for (const auto& [text, workers] : {std::pair{"2", 2}, std::pair{"+2", 2}, std::pair{"02", 2}, std::pair{" 2 ", 2}}) {
    ConfigBuilder b;
    b.set(std::string("engine.workers=") + text);  // spaces around '=' are the --set syntax's
    EXPECT_EQ(b.build().engine.workers, workers) << text;
  }
  for (const auto& [text, seed] : {std::pair{"0x5eed", 0x5eedull}, std::pair{"24301", 24301ull},
                                   std::pair{"0XFFFFFFFFFFFFFFFF", ~0ull}}) {
    ConfigBuilder b;
    b.set(std::string("estimator.seed=") + text);
    EXPECT_EQ(b.build().estimator.seed, seed) << text;
  }
  const std::string big_seed = error_of([] { ConfigBuilder().set("estimator.seed=0x10000000000000000"); });
  EXPECT_NE(big_seed.find("estimator.seed = 0x10000000000000000 is out of range"), std::string::npos) << big_seed;
  const std::string bad_seed = error_of([] { ConfigBuilder().set("estimator.seed=0x5eedz"); });
  EXPECT_NE(bad_seed.find("'0x5eedz' is not a valid integer (decimal or 0x hex digits; allowed: "), std::string::npos)
      << bad_seed;
  ConfigBuilder floats;
  floats.set("estimator.inlier_tolerance_us=1e3");
  floats.set("estimator.outlier_fraction=.25");
  EXPECT_EQ(floats.build().estimator.inlier_tolerance_us, 1000.0);
  EXPECT_EQ(floats.build().estimator.outlier_fraction, 0.25);
  for (const std::string text : {"nan", "inf", "-inf", ".inf", "1e400", "0x1p3", "1,5"}) {
    const std::string err = error_of([&] { ConfigBuilder().set("estimator.inlier_tolerance_us=" + text); });
    EXPECT_NE(err.find("estimator.inlier_tolerance_us = '" + text + "' is not a valid number (allowed: "),
              std::string::npos)
        << err;
  }
}

TEST(Config, SetOverridesFileAndDefaults) {
  const auto path = write_temp("partial.yaml",
                               "estimator:\n"
                               "  window_size: 7\n"
                               "  inlier_tolerance_us: 250\n");
  ConfigBuilder b;
  b.load_file(path);
  b.set("estimator.window_size=9");
  b.set("estimator.regularization = false");
  b.set("estimator.seed=0x10");
  b.set("estimator.sensor.width=346");
  b.set("estimator.sensor.height=260");  // a size is both keys (one alone: ConfigError)
  const Config c = b.build();
  EXPECT_EQ(c.estimator.window_size, 9);              // --set beats the file
  EXPECT_EQ(c.estimator.inlier_tolerance_us, 250.0);  // from the file
  EXPECT_FALSE(c.estimator.regularization);
  EXPECT_EQ(c.estimator.seed, 16u);
  EXPECT_EQ(c.estimator.sensor.width, 346);
  EXPECT_EQ(c.estimator.outlier_fraction, LifetimeOptions{}.outlier_fraction);  // untouched
  ASSERT_NE(b.origin("estimator.window_size"), nullptr);
  EXPECT_TRUE(b.origin("estimator.window_size")->by_user);
  EXPECT_EQ(b.origin("estimator.max_lifetime_us"), nullptr);
}

TEST(Config, MissingFileNamesIt) {
  const std::string msg = error_of([] { ConfigBuilder().load_file("/nonexistent/evlife.yaml"); });
  EXPECT_NE(msg.find("/nonexistent/evlife.yaml"), std::string::npos) << msg;
}

TEST(Config, SyntaxErrorNamesFileAndLine) {
  const auto path = write_temp("syntax.yaml", "estimator:\n  window_size: 5\n   bad: [\n");
  const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
  EXPECT_NE(msg.find(path + ":"), std::string::npos) << msg;
}

// YAML allows keys that are not names (empty, sequences, maps): a clear
// error naming the line, not yaml-cpp's exception (a fuzzer found this:
// tests/fuzz/regressions/config/non_scalar_key.yaml).
TEST(Config, KeyThatIsNotANameIsAnError) {
  for (const char* text : {"estimator:\n  ? [a, b]\n  : 1\n", "? {x: 1}\n: 2\n", "estimator:\n  ? \n  : 3\n"}) {
    const auto path = write_temp("key.yaml", text);
    const std::string msg = error_of([&] { ConfigBuilder().load_file(path); });
    EXPECT_NE(msg.find(path + ":"), std::string::npos) << msg;
    EXPECT_NE(msg.find("expected a key name"), std::string::npos) << msg;
  }
}

// PowerShell 5 writes UTF-16 with a byte-order mark; YAML reads it (a text
// file with NUL bytes, unlike a binary one, which is refused as such).
TEST(Config, Utf16FileReadsAsYaml) {
  const std::string text = "estimator:\n  window_size: 7\n";
  std::string utf16 = "\xFF\xFE";
  for (const char c : text) utf16 += std::string{c, '\0'};
  const auto path = write_temp("utf16.yaml", utf16);
  ConfigBuilder b;
  b.load_file(path);
  EXPECT_EQ(b.build().estimator.window_size, 7);
  const auto binary = write_temp("binary.yaml", std::string("\x89PNG\r\n\x1a\n\0\0\0\rIHDR", 16));
  const std::string msg = error_of([&] { ConfigBuilder().load_file(binary); });
  EXPECT_NE(msg.find("not a YAML text file (a NUL byte at offset 8)"), std::string::npos) << msg;
}

TEST(Config, DumpReadsBackIdentically) {
  ConfigBuilder b;
  b.set("estimator.window_size=11");
  b.set("estimator.lambda_decay_per_us=0.0123456789");
  const Config c = b.build();
  const auto path = write_temp("dump.yaml", evlife::config::to_yaml(c));
  ConfigBuilder b2;
  b2.load_file(path);
  const Config c2 = b2.build();
  EXPECT_EQ(c2.estimator.window_size, 11);
  EXPECT_EQ(c2.estimator.lambda_decay_per_us, 0.0123456789);
}

}  // namespace
