"""evldt from Python: recording readers, the deterministic line pipeline, the evaluator and the
simulator of the C++ core, on numpy arrays; and the LCM message types (evldt.segment_list_t, ...).

    import evldt
    events, width, height, fmt = evldt.read("recording.raw")
    pipeline = evldt.Pipeline(width, height, whole_lines=True)
    steps = pipeline.process(events)          # the segments of every 10 ms output step
    print(steps[steps["t"] == steps["t"].max()])
    whole = pipeline.whole_lines()            # the whole lines of the same steps, with their ids

Parameters are the command-line flags of the tools, with underscores (block_size=14 is
--block-size 14) and checked as the tools check them; a bad one raises ValueError with their
message. Long calls release the GIL.
"""

import struct
from collections import namedtuple

import numpy as np

from ._evldt import (EVENT_DTYPE, GROUND_TRUTH_DTYPE, SEGMENT_DTYPE, FormatError, FrameError, Reader)
from . import _evldt
from .event_batch_t import event_batch_t
from .line_segment_t import line_segment_t
from .segment_list_t import segment_list_t
from .stats_t import stats_t

__all__ = ["read", "read_chunks", "read_frames", "read_lcm_log", "Recording", "Pipeline", "evaluate", "simulate", "Simulation",
           "Subscriber", "LineList",
           "EVENT_DTYPE", "SEGMENT_DTYPE", "GROUND_TRUTH_DTYPE", "STATUS_NAMES", "FormatError", "FrameError", "event_batch_t",
           "line_segment_t", "segment_list_t", "stats_t"]

#: SEGMENT_DTYPE's status codes.
STATUS_NAMES = ("detected", "good", "bad")

Recording = namedtuple("Recording", "events width height format")
Simulation = namedtuple("Simulation", "events ground_truth width height")


def _flags(params):
    """Keyword parameters as the tools' command-line flags."""
    flags = []
    for name, value in params.items():
        if value is None:
            continue
        if isinstance(value, (list, tuple)):
            value = ",".join(str(v) for v in value)
        flags += ["--" + name.replace("_", "-"), str(value)]
    return flags


def read_chunks(path, chunk_events=1_000_000, format=None, channel="", time_slack_us=1000):
    """Yields the events of a recording as structured arrays (EVENT_DTYPE: t, x, y, p) of about
    chunk_events each, in file order: every format evldt-offline reads. A corrupt file raises
    FormatError after the chunks before the fault."""
    if chunk_events < 1:
        raise ValueError("chunk_events must be at least 1")
    reader = Reader(str(path), format or "", channel, time_slack_us)
    while True:
        chunk = reader.read(chunk_events)
        if chunk is None:
            return
        yield chunk


def read(path, format=None, channel="", time_slack_us=1000):
    """A whole recording: Recording(events, width, height, format), where width and height are
    None when the file does not say and format names the reader (as evldt-offline logs it). A
    corrupt file raises FormatError (read_chunks yields the events before the fault first)."""
    reader = Reader(str(path), format or "", channel, time_slack_us)
    chunks = []
    while True:
        chunk = reader.read(1 << 22)
        if chunk is None:
            break
        chunks.append(chunk)
    events = np.concatenate(chunks) if chunks else np.empty(0, dtype=EVENT_DTYPE)
    width, height = reader.sensor if reader.sensor is not None else (None, None)
    return Recording(events, width, height, reader.name)


def _column(values, dtype, name):
    """A column as `dtype`, without a copy where it already is; values out of range raise
    ValueError instead of wrapping around."""
    array = np.asarray(values)
    if array.dtype == dtype:
        return array
    if array.dtype == np.bool_:  # polarity as on/off
        return array.astype(dtype)
    if not np.issubdtype(array.dtype, np.integer):
        raise ValueError(f"{name} must be integers, not {array.dtype}")
    info = np.iinfo(dtype)
    if array.size and (array.min() < info.min or array.max() > info.max):
        raise ValueError(f"{name} values must lie in [{info.min}, {info.max}]")
    return array.astype(dtype)


class Pipeline:
    """The deterministic pipeline of evldt-offline (validation, noise filters, SCARF storage,
    detection, tracking) for a width x height sensor. process() returns the segments of each output
    step (every output_period_us of event time) the events completed, as a SEGMENT_DTYPE array:
    the rows evldt-offline writes to its CSV for the same events and parameters. With
    whole_lines=True, whole_lines() then returns the whole lines of those steps: the rows of
    evldt-offline's --whole-lines CSV (score = the block segments joined)."""

    def __init__(self, width, height, output_period_us=10_000, config=None, whole_lines=False, **params):
        if config is not None:
            params["config"] = str(config)
        self._impl = _evldt.Pipeline(int(width), int(height), _flags(params), int(output_period_us), bool(whole_lines))

    def process(self, events, x=None, y=None, p=None):
        """process(events) with a structured array (fields t, x, y, p), or process(t, x, y, p)."""
        if x is None:
            events = np.asarray(events)
            if events.dtype.names is None or not {"t", "x", "y", "p"} <= set(events.dtype.names):
                raise ValueError("events must be a structured array with fields t, x, y, p (or pass t, x, y, p)")
            t, x, y, p = events["t"], events["x"], events["y"], events["p"]
        else:
            t = events
        return self._impl.process(_column(t, np.int64, "t"), _column(x, np.uint16, "x"), _column(y, np.uint16, "y"),
                                  _column(p, np.int8, "p"))

    def segments(self):
        """The live segments now (SEGMENT_DTYPE, t = the newest event time)."""
        return self._impl.segments()

    def whole_lines(self):
        """The whole lines of the output steps the last process() call completed (SEGMENT_DTYPE,
        by step and id); empty unless made with whole_lines=True."""
        return self._impl.whole_lines()

    def counters(self):
        """Events accepted and dropped, rounds run, lines created and live."""
        return self._impl.counters()


def evaluate(segments, ground_truth, width, height, tolerances=(0.01, 0.02), output_period_us=0, min_normal_speed=None):
    """evldt-eval's figures for predicted segments (SEGMENT_DTYPE, or any structured array with t,
    id, x0, y0, x1, y1, and normal_velocity if known) against ground truth (GROUND_TRUTH_DTYPE: t, gt_id, x0, y0, x1, y1),
    as a dict with the keys of a run of `evldt-eval --json` (docs/tools.md): "accuracy" (precision,
    recall and F at each tolerance, a fraction of the image diagonal), "lifetime", "tracking" (IDF1,
    id switches and their causes; vel_err_med and vel_rel_med compare normal velocities, None where
    the rows carry none), "coverage", "cumulative_per_second", "mean_segments_per_step". An undefined
    ratio is None. output_period_us 0: the median spacing of the predicted steps. With
    min_normal_speed (px/s; evldt-eval --visible-only's 2 is the usual), also "visible_only": the
    score against the true edges moving across themselves at that speed or more, and their share
    of the true pixels."""
    predicted = np.zeros(len(segments), dtype=SEGMENT_DTYPE)
    for field in ("t", "id", "x0", "y0", "x1", "y1"):
        predicted[field] = segments[field]
    for field in ("normal_velocity", "normal_velocity_std"):
        predicted[field] = segments[field] if field in segments.dtype.names else np.nan
    truth = np.zeros(len(ground_truth), dtype=GROUND_TRUTH_DTYPE)
    for field in GROUND_TRUTH_DTYPE.names:
        truth[field] = ground_truth[field]
    return _evldt.evaluate(predicted, truth, int(width), int(height), [float(t) for t in tolerances],
                           int(output_period_us), None if min_normal_speed is None else float(min_normal_speed))


def read_frames(path, width, height, topic=""):
    """The intensity frames of a folder in the Event Camera Dataset's layout (images.txt and images/;
    evldt-sim --frames-hz writes one), of a ROS 1 or 2 bag's (.bag, .db3, .mcap) sensor_msgs/Image topic (mono8, mono16, bgr8
    or rgb8, read as grey), of an HDF5 file in MVSEC's layout (/davis/left/image_raw and its _ts
    times), of an AEDAT 4.0, 3.1 or jAER 2.0 DAVIS recording, or of a video file; ``topic`` picks the bag's topic or the HDF5 dataset (empty: the first / the left camera).
    A list of (t_us, image), image a height x width uint8 array, in time order. A frame that is
    missing, unreadable, of another size, of another pixel encoding or out of time order raises
    FrameError (a ValueError) naming it."""
    return _evldt.read_frames(str(path), int(width), int(height), str(topic))


def simulate(scene, gt_period_us=10_000, **options):
    """A built-in scene (the names evldt-sim --list gives) through the event simulator:
    Simulation(events, ground_truth, width, height). Options are evldt-sim's flags (duration_s,
    seed, motion_seed, contrast, noise_rate_hz, ...)."""
    if gt_period_us < 1:
        raise ValueError("gt_period_us must be at least 1")
    events, truth, width, height = _evldt.simulate(["--scene", str(scene)] + _flags(options), int(gt_period_us))
    return Simulation(events, truth, width, height)


_LCM_LOG_SYNC = 0xEDA1DA01
_LCM_LOG_HEADER = struct.Struct(">IqqII")  # sync, event number, utime, channel length, data length


def read_lcm_log(path):
    """Yields (channel, utime, data) for each message of an lcm-log (the file lcm-logger writes),
    without the lcm module; lcm.EventLog does the same where the lcm module is installed. A cut or
    corrupt record raises FormatError after the records before it."""
    with open(path, "rb") as f:
        offset = 0
        while True:
            header = f.read(_LCM_LOG_HEADER.size)
            if not header:
                return
            if len(header) < _LCM_LOG_HEADER.size:
                raise FormatError(f"{path}: byte {offset}: the log ends inside a record header")
            sync, _, utime, channel_length, data_length = _LCM_LOG_HEADER.unpack(header)
            if sync != _LCM_LOG_SYNC:
                raise FormatError(f"{path}: byte {offset}: no record starts here (sync word {sync:#010x})")
            body = f.read(channel_length + data_length)
            if len(body) < channel_length + data_length:
                raise FormatError(f"{path}: byte {offset}: the log ends inside a record")
            yield body[:channel_length].decode("utf-8", "replace"), utime, body[channel_length:]
            offset += _LCM_LOG_HEADER.size + channel_length + data_length


LineList = namedtuple("LineList", "whole_lines camera t_us lines")


class Subscriber:
    """A camera's segment and whole-line lists from a running evldt-lines, through evldt's C++ consumer
    SDK (no lcm Python module needed). `url`: an LCM URL, or empty for LCM_DEFAULT_URL / LCM's default.

        for lines in evldt.Subscriber("cam0").lists(timeout_s=5):
            print(lines.whole_lines, lines.t_us, lines.lines["id"])

    Each list is a LineList: whole_lines (WHOLE_LINES_<CAMERA> or LINES_<CAMERA>), camera, t_us (the
    lattice state's event time) and lines (SEGMENT_DTYPE; first_seen and last_good are 0, the
    normal velocities those on the bus)."""

    def __init__(self, camera="cam0", url=""):
        self._impl = _evldt.Subscriber(str(camera), str(url))

    def receive(self, timeout_s=1.0):
        """The next list, or None when none came within timeout_s."""
        received = self._impl.receive(int(timeout_s * 1000))
        return None if received is None else LineList(*received)

    def lists(self, timeout_s=None):
        """Yields lists as they come; ends after timeout_s without one (None: never; a running
        evldt-lines publishes at its output rate, so a silence means it stopped)."""
        while True:
            received = self.receive(1.0 if timeout_s is None else timeout_s)
            if received is not None:
                yield received
            elif timeout_s is not None:
                return

    @property
    def undecodable(self):
        """Messages on the camera's channels that did not decode as segment lists."""
        return self._impl.undecodable
