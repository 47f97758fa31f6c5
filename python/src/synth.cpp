// evlife.synth: the synthetic scenes of `evlife synth` (bars, a texture;
// ideal or DVS pixels) as NumPy arrays, with their ground truth per event.
#include <algorithm>
#include <cstddef>
#include <cstdio>
#include <new>
#include <string>
#include <string_view>
#include <vector>

#include "bindings.h"
#include "dtypes.h"
#include "errors.h"
#include "evlife/io/synthetic_scene.h"
#include "evlife/io/textured_scene.h"
#include "options.h"

namespace evlife::python {
namespace {

// Offsets from io::EventTruth itself: the layout is stated once.
py::dtype make_truth_dtype() {
  using io::EventTruth;
  py::dict d;
  d["names"] = py::make_tuple("t_true", "lifetime", "nx", "ny", "travel_px", "feature", "margin_px", "burst_index",
                              "noise", "hot", "scorable");
  d["formats"] = py::make_tuple("<f8", "<f8", "<f8", "<f8", "<f8", "<i2", "<u2", "u1", "?", "?", "?");
  d["offsets"] = py::make_tuple(offsetof(EventTruth, t_true_us), offsetof(EventTruth, lifetime_us),
                                offsetof(EventTruth, nx), offsetof(EventTruth, ny), offsetof(EventTruth, travel_px),
                                offsetof(EventTruth, feature), offsetof(EventTruth, margin_px),
                                offsetof(EventTruth, burst_index), offsetof(EventTruth, is_noise),
                                offsetof(EventTruth, is_hot), offsetof(EventTruth, scorable));
  d["itemsize"] = sizeof(EventTruth);
  return py::dtype::from_args(d);
}

py::dtype truth_dtype() {
  static auto* dtype = new py::dtype(make_truth_dtype());  // leaked: see dtypes.cpp
  return *dtype;
}

// MemoryError naming the scene's size and what to lower; `bytes` > 0: what
// its background alone needs.
[[noreturn]] void throw_memory_error(const io::SceneSpec& spec, double duration_s, double bytes) {
  char needs[64] = "";
  if (bytes > 0) std::snprintf(needs, sizeof needs, ", its background alone %.3g GB", bytes * 1e-9);
  char text[384];
  std::snprintf(text, sizeof text,
                "synth: the scene's events do not fit in memory (sensor %dx%d, %g s, noise_rate %g per pixel per "
                "second%s): shorten the duration, lower noise_rate or the sensor, or let `evlife synth` stream the "
                "scene to a file and read it in chunks (evlife.Reader)",
                spec.sensor.width, spec.sensor.height, duration_s, spec.noise_rate_hz_per_px, needs);
  PyErr_SetString(PyExc_MemoryError, text);
  throw py::error_already_set();
}

constexpr const char* kWhere = "evlife.synth";

// The keyword options besides the arguments: the pixel parameters of `evlife
// synth` ('-' -> '_'), noise_rate, jitter_us.
std::vector<std::string> option_names() {
  std::vector<std::string> names = {"noise_rate", "jitter_us"};
  for (const io::PixelParameter& p : io::pixel_parameters()) {
    std::string py_name = p.name;
    for (char& c : py_name) c = c == '-' ? '_' : c;
    names.push_back(py_name);
  }
  return names;
}

py::tuple synth(const StrArgument& scene_arg, const py::object& sensor_arg, const FloatArgument& duration_arg,
                const IntArgument& seed_arg, const py::object& pixel_arg, const py::kwargs& pixel_options) {
  // A keyword that is none of the function's: named, with the one it misspells.
  const std::vector<std::string> options = option_names();
  std::vector<std::string_view> keywords = {"scene", "sensor", "duration", "seed", "pixel"};
  keywords.insert(keywords.end(), options.begin(), options.end());
  py::dict unknown;
  for (const auto& [key, value] : pixel_options)
    if (std::find(options.begin(), options.end(), py::str(key).cast<std::string>()) == options.end())
      unknown[key] = value;
  refuse_keywords(kWhere, unknown, keywords);
  const std::string scene_name = str_argument(kWhere, "scene", scene_arg);
  const SensorSize sensor = sensor_arg.is_none() ? SensorSize{128, 128} : sensor_from_python(sensor_arg);
  const double duration_s = float_argument(kWhere, "duration", duration_arg, "seconds");
  const auto seed = int_argument<std::uint64_t>(kWhere, "seed", seed_arg, "", 0);
  if (!(duration_s >= 1e-3 && duration_s <= 3600.0)) throw py::value_error("duration: expected 0.001 .. 3600 s");
  const auto duration_us = static_cast<std::int64_t>(duration_s * 1e6 + 0.5);
  io::SceneSpec spec;
  const bool textured = scene_name == "textured";
  // As `evlife synth`: DVS pixels for the texture, ideal ones for the bars.
  if (!pixel_arg.is_none() && !py::isinstance<py::str>(pixel_arg))  // pybind's cast error named nothing
    throw py::type_error("pixel: expected 'ideal', 'dvs' or 'dvs-dim', got " +
                         py::str(py::type::of(pixel_arg).attr("__name__")).cast<std::string>());
  const std::string pixel_name = pixel_arg.is_none() ? (textured ? "dvs" : "ideal") : pixel_arg.cast<std::string>();
  if (!textured) {
    const auto preset = io::scene_preset(scene_name, sensor, duration_us, seed);
    if (!preset) {
      throw py::value_error("scene '" + scene_name + "': expected edges, bar, mixed, large, edges-bar or textured");
    }
    spec = *preset;
  } else {
    spec.duration_us = duration_us;
    spec.seed = seed;
  }
  if (!io::apply_pixel_setting(spec, pixel_name)) {
    throw py::value_error("pixel '" + pixel_name + "': expected ideal, dvs or dvs-dim");
  }
  if (textured && !spec.pixel.enabled) throw py::value_error("scene 'textured': needs pixel='dvs' or 'dvs-dim'");
  // Keyword options: the pixel parameters of `evlife synth` ('-' -> '_'),
  // noise_rate, jitter_us.
  for (const auto& [key, value] : pixel_options) {
    const auto name = key.cast<std::string>();
    if (py::isinstance<py::str>(value) || py::isinstance<py::bytes>(value))  // "5" is text
      raise_argument_type_error(kWhere, name.c_str(), "a number", value);
    const double v = float_argument(kWhere, name.c_str(), value, "");
    if (name == "noise_rate") {
      if (!(v >= 0.0 && v <= 1e4)) throw py::value_error("noise_rate: expected 0 .. 1e4 events per pixel per second");
      spec.noise_rate_hz_per_px = v;
      continue;
    }
    if (name == "jitter_us") {
      if (spec.pixel.enabled)  // as `evlife synth --jitter-us`: the pixel model has its latency jitter
        throw py::value_error("jitter_us is the ideal pixels' timing; with pixel='" + pixel_name + "': latency_jitter_us");
      if (!(v >= 0.0 && v <= 1e5)) throw py::value_error("jitter_us: expected 0 .. 1e5");
      spec.jitter_sigma_us = v;
      continue;
    }
    bool known = false;
    for (const io::PixelParameter& p : io::pixel_parameters()) {
      std::string py_name = p.name;
      for (char& c : py_name) c = c == '-' ? '_' : c;
      if (py_name != name) continue;
      if (!spec.pixel.enabled) throw py::value_error(name + ": needs pixel='dvs' or 'dvs-dim'");
      if (textured && name == "contrast") throw py::value_error("contrast: the textured scene's leaves set the contrasts");
      if (!(v >= p.lo && v <= p.hi)) {
        throw py::value_error(name + ": expected " + std::to_string(p.lo) + " .. " + std::to_string(p.hi));
      }
      spec.pixel.*p.field = v;
      known = true;
    }
    if (!known) throw py::type_error(unexpected_keyword(kWhere, name));  // (refused above)
  }
  spec.sensor = sensor;
  const io::TexturedSceneSpec texture = io::textured_scene_like(spec);
  if (const std::string why = textured ? io::validate_textured_scene_spec(texture) : io::validate_scene_spec(spec);
      !why.empty()) {
    throw py::value_error(why);
  }
  // The background alone (noise, hot pixels) over the whole duration, held at
  // once with its truth: refused up front, where the allocation failed after a
  // minute of paging (a lower bound: the edges' events come on top).
  const double background_bytes = io::background_events_per_s(sensor, spec.noise_rate_hz_per_px, spec.pixel) *
                                  duration_s * static_cast<double>(sizeof(Event) + sizeof(io::EventTruth));
  if (const auto available = io::available_memory_bytes(); available && background_bytes > static_cast<double>(*available))
    throw_memory_error(spec, duration_s, background_bytes);  // the command line's rule (memory_check.h)
  io::SyntheticScene scene;
  SignalCheck signals;  // Ctrl-C: minutes of a long scene were deaf to it
  try {
    ReleasedGil release;
    const io::GenerationStop stop = [&signals] { return signals.pending(); };
    scene = textured ? io::generate_textured_scene(texture, stop) : io::generate_scene(spec, stop);
  } catch (const std::bad_alloc&) {  // pybind11 said only "std::bad_alloc"
    throw_memory_error(spec, duration_s, 0.0);
  }
  if (!scene.complete || signals.pending_now()) {
    const std::size_t n = scene.complete ? scene.events.size() : scene.generated_events;
    scene = {};  // its memory back before the exception travels
    SignalCheck::raise("synth: interrupted after " + std::to_string(n) + " of the scene's events were generated",
                       py::none(), n, py::none());
  }
  py::list names;
  for (const std::string& n : scene.feature_names) names.append(n);
  // Adopted, not copied: a copy held the GIL for seconds of a large scene and doubled its memory.
  return py::make_tuple(adopt(std::move(scene.events), event_dtype()), adopt(std::move(scene.truth), truth_dtype()),
                        names);
}

}  // namespace

void bind_synth(py::module_& m) {
  m.attr("TRUTH_DTYPE") = truth_dtype();
  m.def("synth", &synth, py::arg("scene") = "mixed", py::arg("sensor") = py::none(), py::arg("duration") = 3.0,
        py::arg("seed") = 1, py::arg("pixel") = py::none(),
        "A synthetic scene with known ground truth, as `evlife synth` writes it: (events, truth, "
        "features). events: EVENT_DTYPE, time-ordered; truth: TRUTH_DTYPE, truth[i] for events[i] "
        "(lifetime in us, 0 for noise; (nx, ny) the unit direction the edge moves; feature an index "
        "into features; scorable False where no plane or no score applies); features: the "
        "patterns' or tiles' names. scene: edges, bar, mixed, large, edges-bar, textured "
        "(needs pixel='dvs' or 'dvs-dim'); duration in seconds; pixel: ideal, dvs, dvs-dim (default "
        "dvs for textured, ideal for the bars); "
        "keywords: the pixel options of `evlife synth` with '_' for '-' (latency_us=300, "
        "cutoff_hz=100, ...), noise_rate, jitter_us. The same arguments give the same arrays. "
        "A scene whose background alone exceeds the memory raises MemoryError before generating; "
        "Ctrl-C raises evlife.Interrupted (events_processed: the events generated, dropped).");
}

}  // namespace evlife::python
