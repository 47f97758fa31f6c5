// evlife.frame: the frame `evlife render` draws at one instant, from an
// augmented array in memory. The same cursor, active-event set, fixed-window
// map and composer as the CLI; only the source is the array.
#include <opencv2/imgproc.hpp>

#include <algorithm>
#include <cstring>
#include <string>

#include "bindings.h"
#include "dtypes.h"
#include "errors.h"
#include "evlife/algo/active_event_map.h"
#include "evlife/io/augmented_event_reader.h"
#include "evlife/render/augmented_source.h"
#include "evlife/render/fixed_window_map.h"
#include "evlife/render/frame_clock.h"
#include "evlife/render/frame_composer.h"
#include "evlife/render/frame_memory.h"
#include "evlife/render/render_cursor.h"
#include "options.h"

namespace evlife::python {
namespace {

/// The augmented array as the renderer's source.
class ArraySource final : public render::AugmentedSource {
 public:
  ArraySource(std::span<const AugmentedEvent> events, SensorSize sensor)
      : events_(events), sensor_(sensor) {}
  std::size_t read(std::span<AugmentedEvent> out) override {
    const std::size_t n = std::min(out.size(), events_.size() - pos_);
    std::copy_n(events_.data() + pos_, n, out.data());
    pos_ += n;
    return n;
  }
  SensorSize sensor() const override { return sensor_; }
  std::string description() const override { return "array"; }
  const LifetimeStats* estimator_stats() const override { return nullptr; }

 private:
  std::span<const AugmentedEvent> events_;
  std::size_t pos_ = 0;
  SensorSize sensor_;
};

py::array frame(const py::array& augmented, std::int64_t t_us, const py::object& sensor_obj,
                const StrArgument& mode_arg, const StrArgument& color_arg, const py::object& scale_obj,
                const BoolArgument& caption_arg, const BoolArgument& legend_arg, const BoolArgument& thinning_arg,
                std::pair<double, double> range_ms) {
  if (!is_exact(augmented, augmented_dtype())) {
    throw py::type_error("frame: expected a 1-D contiguous array of evlife.AUGMENTED_DTYPE");
  }
  const std::string mode = str_argument("evlife.frame", "mode", mode_arg);
  const std::string color = str_argument("evlife.frame", "color", color_arg);
  const bool caption = bool_argument("evlife.frame", "caption", caption_arg);
  const bool legend = bool_argument("evlife.frame", "legend", legend_arg);
  const bool thinning = bool_argument("evlife.frame", "thinning", thinning_arg);
  const std::span events(static_cast<const AugmentedEvent*>(augmented.data()),
                         static_cast<std::size_t>(augmented.shape(0)));
  SensorSize sensor;
  if (!sensor_obj.is_none()) {
    sensor = sensor_from_python(sensor_obj);
  } else {
    for (const auto& a : events) {
      sensor.width = std::max(sensor.width, a.event.x + 1);
      sensor.height = std::max(sensor.height, a.event.y + 1);
    }
  }
  if (sensor.width < 1 || sensor.height < 1 || sensor.width > 4096 || sensor.height > 4096) {
    throw py::value_error("frame: sensor " + std::to_string(sensor.width) + "x" +
                          std::to_string(sensor.height) + " is not usable (1..4096 each)");
  }
  if (events.empty()) throw py::value_error("frame: the array holds no event: nothing to draw");
  // As `evlife render` refuses such a file.
  const io::RecordFault bad = io::first_unreadable_record(events, sensor, INT64_MIN);
  if (bad.index < events.size()) {
    raise_input_error(io::ReadError("augmented", -1, static_cast<std::int64_t>(bad.index), bad.what));
  }
  // As `evlife render`'s options (its defaults when not given).
  render::FrameStyle style;
  style.color = render::parse_color_mode(color);  // std::invalid_argument: ValueError
  if (scale_obj.is_none()) {
    style.scale = render::FrameStyle::default_scale(sensor.width, sensor.height);
  } else {
    try {
      style.scale = py::int_(scale_obj.attr("__index__")()).cast<int>();  // 2.5 is no scale: no truncation
    } catch (const py::error_already_set&) {
      throw py::type_error("frame: scale must be a whole number, got " + py::repr(scale_obj).cast<std::string>());
    } catch (const py::cast_error&) {
      throw py::value_error("frame: scale must be 1.." + std::to_string(render::FrameStyle::kMaxScale));
    }
    if (style.scale < 1 || style.scale > render::FrameStyle::kMaxScale)
      throw py::value_error("frame: scale must be 1.." + std::to_string(render::FrameStyle::kMaxScale));
  }
  style.caption = caption;
  style.legend = legend;
  constexpr double kMaxMs = render::FrameStyle::kMaxLifetimeRangeMs;  // as render --lifetime-range
  if (!(range_ms.first > 0.0) || !(range_ms.second > range_ms.first) || !(range_ms.second <= kMaxMs)) {
    throw py::value_error("frame: lifetime_range_ms must be (MIN, MAX) with 0 < MIN < MAX <= 1e9, got (" +
                          py::repr(py::float_(range_ms.first)).cast<std::string>() + ", " +
                          py::repr(py::float_(range_ms.second)).cast<std::string>() + ")");
  }
  style.lifetime_min_us = 1000.0 * range_ms.first;
  style.lifetime_max_us = 1000.0 * range_ms.second;
  render::FrameComposer composer(render::parse_view_mode(mode), style, mode);
  // As `evlife render`: a frame too large is refused before OpenCV's "Insufficient memory".
  if (const auto refusal = render::frame_memory_refusal(composer.frame_size(sensor))) {
    PyErr_SetString(PyExc_MemoryError, ("frame: " + *refusal + " (sensor " + std::to_string(sensor.width) + "x" +
                                        std::to_string(sensor.height) + " at scale " + std::to_string(style.scale) +
                                        "): lower scale")
                                           .c_str());
    throw py::error_already_set();
  }

  cv::Mat rgb;
  {
    ReleasedGil release;
    ArraySource source(events, sensor);
    ActiveEventMap set(sensor, thinning);
    render::FixedWindowMap window(sensor);
    render::RenderCursor cursor(source, set, &window);
    const std::int64_t first_t = *cursor.first_t_us();
    cursor.advance_to(t_us);
    // The caption's time from the first event, saturated (t_us - first_t overflowed at -2^63: "t = +9.2e12 s").
    const std::int64_t rel_us =
        t_us >= first_t ? render::clock_span_us(first_t, t_us) : -render::clock_span_us(t_us, first_t);
    const cv::Mat& bgr = composer.compose(set, window, t_us, rel_us);
    cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  }
  py::array_t<std::uint8_t> out({rgb.rows, rgb.cols, 3});
  for (int r = 0; r < rgb.rows; ++r) {
    std::memcpy(out.mutable_data(r, 0, 0), rgb.ptr(r), static_cast<std::size_t>(rgb.cols) * 3);
  }
  return out;
}

}  // namespace

void bind_frame(py::module_& m) {
  m.def("_frame", &frame, py::arg("augmented"), py::arg("t_us"), py::arg("sensor"),
        py::arg("mode"), py::arg("color"), py::arg("scale"), py::arg("caption"),
        py::arg("legend"), py::arg("thinning"), py::arg("lifetime_range_ms"),
        "Internal: evlife.frame on an exact AUGMENTED_DTYPE array.");
}

}  // namespace evlife::python
