# Type stubs of the evlife package (the compiled part is evlife._evlife).
from os import PathLike
from typing import Any, Iterator, Literal, Mapping, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

from . import batch as batch

StrPath = Union[str, bytes, PathLike[str], PathLike[bytes]]
Sensor = Tuple[int, int]

EVENT_DTYPE: np.dtype[np.void]      # t int64 µs, x uint16, y uint16, p int8 (+1/-1); 16 bytes
AUGMENTED_DTYPE: np.dtype[np.void]  # + lifetime, vx, vy, prediction_error float32; 32 bytes
TRUTH_DTYPE: np.dtype[np.void]      # synth's ground truth: t_true, lifetime, nx, ny, travel_px float64,
                                    # feature int16, margin_px uint16, burst_index uint8, noise, hot, scorable bool

class InputError(ValueError):
    path: str
    byte_offset: int
    event_index: int
    partial: Optional[npt.NDArray[np.void]]
    events_written: Optional[int]  # process_file: the events its output holds

class Interrupted(KeyboardInterrupt):  # Ctrl-C during read(), Reader.read(), scan(), process(), process_file(), synth() or LifetimeEstimator.process()
    partial: Optional[npt.NDArray[np.void]]  # the outputs of the events processed
    events_processed: int
    events_written: Optional[int]  # process_file: the events its output holds

def formats() -> list[Tuple[str, str]]: ...
def read(path: StrPath, sensor: Optional[Sensor] = None, *, from_s: Optional[float] = None,
         to_s: Optional[float] = None, topic: Optional[str] = None,
         time_unit: Optional[Literal["s", "ms", "us", "ns"]] = None,
         polarity: Optional[Literal["on", "off", "both"]] = None) -> npt.NDArray[np.void]: ...

class Reader:
    @property
    def sensor(self) -> Optional[Sensor]: ...
    @property
    def format(self) -> str: ...
    @property
    def layout(self) -> str: ...
    @property
    def path(self) -> str: ...
    @property
    def chunk_events(self) -> int: ...
    @property
    def bytes_consumed(self) -> int: ...
    @property
    def skipped_records(self) -> int: ...
    @property
    def skipped_record_kinds(self) -> dict[str, int]: ...
    def read(self, max_events: Optional[int] = None) -> npt.NDArray[np.void]: ...
    def close(self) -> None: ...
    def __iter__(self) -> Iterator[npt.NDArray[np.void]]: ...
    def __next__(self) -> npt.NDArray[np.void]: ...
    def __enter__(self) -> "Reader": ...
    def __exit__(self, *args: Any) -> None: ...

# (for a named pipe: a StreamReader over its temporary copy, with the same interface)
def open(path: StrPath, sensor: Optional[Sensor] = None, chunk_events: int = 1048576, *,
         from_s: Optional[float] = None, to_s: Optional[float] = None,
         topic: Optional[str] = None,
         time_unit: Optional[Literal["s", "ms", "us", "ns"]] = None,
         polarity: Optional[Literal["on", "off", "both"]] = None) -> Reader: ...
def scan(input: StrPath, sensor: Optional[Sensor] = None, *,
         config: Optional[StrPath] = None, topic: Optional[str] = None,
         time_unit: Optional[Literal["s", "ms", "us", "ns"]] = None) -> dict[str, Any]: ...
def read_augmented(path: StrPath) -> Tuple[npt.NDArray[np.void], Optional[Sensor]]: ...
def write(path: StrPath, augmented: npt.NDArray[np.void], sensor: Sensor) -> None: ...

# Keyword options: every `estimator.` key of config/evlife.yaml (see estimator_options()).
class LifetimeEstimator:
    # sensor: required unless config= states estimator.sensor
    def __init__(self, sensor: Optional[Sensor] = None, *, config: Optional[StrPath] = None,
                 window_size: int = ..., outlier_fraction: float = ...,
                 ransac_confidence: float = ..., inlier_tolerance_us: float = ...,
                 inlier_tolerance_lifetime_fraction: float = ...,
                 inlier_tolerance_residual_factor: float = ...,
                 skip_censored_samples: bool = ..., censoring_noise_factor: float = ...,
                 regularization: bool = ...,
                 lambda_offset: float = ..., lambda_gain: float = ...,
                 lambda_decay_per_us: float = ..., lambda_unit_px2: float = ...,
                 fresh_region_span_us: float = ...,
                 continuation_min_support: int = ..., burst_window_lifetimes: float = ...,
                 burst_span_lifetimes: float = ..., max_burst_followers: int = ...,
                 burst_span_timing_noise: float = ...,
                 ramp_follower_span_lifetimes: float = ...,
                 ramp_follower_upstream_lifetimes: float = ...,
                 late_event_keeps_arrival_timing_noise: float = ...,
                 late_follower_upstream_durations: float = ...,
                 prediction_expiry_lifetimes: float = ...,
                 max_lifetime_us: float = ..., max_event_offset_tolerances: float = ...,
                 continuation_max_event_offset_tolerances: float = ...,
                 max_lifetime_standard_error: float = ...,
                 seed: int = ..., **options: Any) -> None: ...
    def process(self, events: Any) -> npt.NDArray[np.void]: ...
    def reset(self) -> None: ...
    @property
    def sensor(self) -> Sensor: ...
    @property
    def options(self) -> dict[str, Any]: ...
    @property
    def stats(self) -> dict[str, int]: ...

def estimator_options(config: Optional[StrPath] = None) -> dict[str, dict[str, Any]]: ...
def process(input: Union[StrPath, Any], sensor: Optional[Sensor] = None, *,
            config: Optional[StrPath] = None, one_thread: bool = False,
            from_s: Optional[float] = None, to_s: Optional[float] = None,
            topic: Optional[str] = None, time_unit: Optional[Literal["s", "ms", "us", "ns"]] = None,
            polarity: Optional[Literal["on", "off", "both"]] = None,
            **options: Any) -> npt.NDArray[np.void]: ...
def process_file(input: StrPath, output: StrPath, sensor: Optional[Sensor] = None, *,
                 config: Optional[StrPath] = None, one_thread: bool = False,
                 from_s: Optional[float] = None, to_s: Optional[float] = None,
                 topic: Optional[str] = None, time_unit: Optional[Literal["s", "ms", "us", "ns"]] = None,
                 polarity: Optional[Literal["on", "off", "both"]] = None,
                 **options: Any) -> dict[str, Any]: ...
def frame(augmented: Any, t_us: int, sensor: Optional[Sensor] = None, mode: str = "lifetime", *,
          color: Literal["lifetime", "polarity", "plain"] = "lifetime",
          scale: Optional[int] = None, caption: bool = True, legend: bool = True,
          thinning: bool = True,
          lifetime_range_ms: Tuple[float, float] = (0.3, 30.0)) -> npt.NDArray[np.uint8]: ...
def synth(scene: Literal["edges", "bar", "mixed", "large", "edges-bar", "textured"] = "mixed",
          sensor: Optional[Sensor] = None, duration: float = 3.0, seed: int = 1,
          pixel: Optional[Literal["ideal", "dvs", "dvs-dim"]] = None,
          **options: float) -> Tuple[npt.NDArray[np.void], npt.NDArray[np.void], list[str]]: ...
