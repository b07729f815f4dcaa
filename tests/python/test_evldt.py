"""The Python module against the C++ tools on the same data: evldt-sim writes the recordings,
evldt-offline and evldt-eval give the figures the module must reproduce.

Run by tests/run.sh (ctest: python_module) with EVLDT_BUILD set to the build folder and the
module's folder on PYTHONPATH."""

import csv
import json
import os
import pathlib
import re
import struct
import subprocess
import sys
import threading
import time

import numpy as np
import pytest

import evldt

BUILD = pathlib.Path(os.environ.get("EVLDT_BUILD", "build/dev"))
SIM = BUILD / "tools/evldt-sim/evldt-sim"
OFFLINE = BUILD / "tools/evldt-offline/evldt-offline"
EVAL = BUILD / "tools/evldt-eval/evldt-eval"
AEDAT4_FIXTURE = BUILD / "tests/aedat4_fixture"
REAL = pathlib.Path(__file__).resolve().parents[2] / ".." / "shared" / "real"


def run(*args, check=True):
    return subprocess.run([str(a) for a in args], capture_output=True, text=True, check=check)


@pytest.fixture(scope="module")
def boxes(tmp_path_factory):
    """0.4 s of boxes-6dof, written by evldt-sim in every format it writes."""
    folder = tmp_path_factory.mktemp("boxes")
    for fmt in ("evt3", "evt2", "evt21", "dat", "ecd"):
        run(SIM, "--scene", "boxes-6dof", "--duration-s", "0.4", "--out-dir", folder / fmt, "--format", fmt, "--quiet")
    return folder


def recording(folder, fmt):
    (path,) = [p for p in (folder / fmt).iterdir() if p.name.startswith("events")]
    return path


def read_csv(path):
    with open(path) as f:
        return list(csv.DictReader(f))


def test_readers_give_the_simulated_events_in_every_format(boxes):
    simulated = evldt.simulate("boxes-6dof", duration_s=0.4)
    assert len(simulated.events) > 50_000
    for fmt in ("evt3", "evt2", "evt21", "dat", "ecd"):
        got = evldt.read(recording(boxes, fmt))
        assert got.events.dtype == evldt.EVENT_DTYPE
        if fmt != "ecd":  # events.txt has no header to say the sensor size
            assert (got.width, got.height) == (simulated.width, simulated.height), fmt
        for field in ("t", "x", "y"):
            np.testing.assert_array_equal(got.events[field], simulated.events[field], err_msg=fmt)
        np.testing.assert_array_equal(got.events["p"] > 0, simulated.events["p"] > 0, err_msg=fmt)


@pytest.mark.parametrize("compression", ["none", "lz4", "zstd"])
def test_the_aedat_librarys_layout_reads_as_dvs(tmp_path, compression):
    # The same scene with each FlatBuffer finished size-prefixed (DV) or plain with its size put in
    # front (the aedat library): the same events and frames.
    for layout in ("dv", "aedat-library"):
        run(AEDAT4_FIXTURE, tmp_path / f"{layout}.aedat4", layout, compression)
    dv, library = (evldt.read(tmp_path / f"{layout}.aedat4") for layout in ("dv", "aedat-library"))
    assert len(dv.events) > 10_000 and (library.width, library.height) == (dv.width, dv.height) == (240, 180)
    np.testing.assert_array_equal(library.events, dv.events)
    dv_frames, library_frames = (evldt.read_frames(tmp_path / f"{layout}.aedat4", 240, 180) for layout in ("dv", "aedat-library"))
    assert len(dv_frames) == len(library_frames) == 14
    for (t_dv, image_dv), (t_library, image_library) in zip(dv_frames, library_frames):
        assert t_dv == t_library
        np.testing.assert_array_equal(image_library, image_dv)


def test_chunks_join_to_the_whole_recording(boxes):
    path = recording(boxes, "evt3")
    chunks = list(evldt.read_chunks(path, chunk_events=10_000))
    assert len(chunks) > 5
    assert all(len(c) == 10_000 for c in chunks[:-1]) and 0 < len(chunks[-1]) <= 10_000
    np.testing.assert_array_equal(np.concatenate(chunks), evldt.read(path).events)


def assert_rows_equal(got, expected):
    """SEGMENT_DTYPE rows against the rows of a segment CSV, to the CSV's precision."""
    assert len(got) == len(expected)
    np.testing.assert_array_equal(got["t"], [int(r["t_us"]) for r in expected])
    np.testing.assert_array_equal(got["id"], [int(r["id"]) for r in expected])
    for field in ("x0", "y0", "x1", "y1"):
        np.testing.assert_allclose(got[field], [float(r[field]) for r in expected], rtol=0, atol=5.1e-4)
    np.testing.assert_allclose(got["score"], [float(r["score"]) for r in expected], rtol=0, atol=5.1e-5)
    for field in ("normal_velocity", "normal_velocity_std"):
        np.testing.assert_allclose(got[field], [float(r[field]) for r in expected], rtol=0, atol=0.051)
    assert [evldt.STATUS_NAMES[s] for s in got["status"]] == [r["status"] for r in expected]


def test_pipeline_output_equals_evldt_offline_csv(boxes, tmp_path):
    path = recording(boxes, "evt3")
    run(OFFLINE, path, "-o", tmp_path / "segments.csv", "--whole-lines", tmp_path / "whole.csv", "-q")
    expected = read_csv(tmp_path / "segments.csv")
    expected_whole = read_csv(tmp_path / "whole.csv")
    rec = evldt.read(path)
    pipeline = evldt.Pipeline(rec.width, rec.height, whole_lines=True)
    # In uneven slices, as a stream arrives: the output may not depend on how the events are cut.
    cuts = [0, 1, 777, 50_000, 123_457, len(rec.events)]
    got, got_whole = [], []
    for a, b in zip(cuts, cuts[1:]):
        got.append(pipeline.process(rec.events[a:b]))
        got_whole.append(pipeline.whole_lines())
    got, got_whole = np.concatenate(got), np.concatenate(got_whole)
    assert len(expected) > 1000 and len(expected_whole) > 100
    assert_rows_equal(got, expected)
    assert (got["first_seen"] <= got["t"]).all() and (got["last_good"] <= got["t"]).all()
    # The whole lines: fewer rows than segments, each joining at least one segment.
    assert_rows_equal(got_whole, expected_whole)
    assert len(got_whole) < len(got) and (got_whole["score"] >= 1).all()
    live = pipeline.segments()
    assert len(live) == pipeline.counters()["lines_live"] > 0


def test_whole_lines_example_draws_or_prints_them(tmp_path):
    example = pathlib.Path(__file__).resolve().parents[2] / "libs/python/examples/plot_whole_lines.py"
    out = run(sys.executable, example, "boxes-6dof", "0.5", tmp_path / "whole.png").stdout
    joined = re.search(r"(\d+) whole lines joining (\d+) of (\d+) segments", out)
    assert joined and 0 < int(joined[1]) < int(joined[2]) <= int(joined[3]), out
    if "matplotlib is not installed" in out:
        assert len(re.findall(r"^ +\d+  \(", out, re.M)) == int(joined[1]), out
    else:
        assert (tmp_path / "whole.png").stat().st_size > 10_000


def test_pipeline_without_whole_lines_gives_none(boxes):
    events = evldt.read(recording(boxes, "evt3")).events
    pipeline = evldt.Pipeline(240, 180)
    assert len(pipeline.process(events)) > 1000
    assert len(pipeline.whole_lines()) == 0


def test_pipeline_takes_separate_columns_and_is_deterministic(boxes):
    events = evldt.read(recording(boxes, "evt3")).events
    a = evldt.Pipeline(240, 180).process(events)
    b = evldt.Pipeline(240, 180).process(events["t"], events["x"].astype(np.int32), events["y"], events["p"])
    np.testing.assert_array_equal(a, b)
    c = evldt.Pipeline(240, 180).process(events["t"], events["x"], events["y"], events["p"] > 0)  # on/off polarity
    np.testing.assert_array_equal(a, c)


def test_python_threads_may_share_a_pipeline(boxes):
    events = evldt.read(recording(boxes, "evt3")).events
    alone = evldt.Pipeline(240, 180).process(events)
    shared = evldt.Pipeline(240, 180)
    halves = np.array_split(np.arange(len(events)), 2)
    results = {}

    def feed(index):  # the halves must go in order: the second waits for the first's turn to end
        results[index] = shared.process(events[halves[index]])

    first = threading.Thread(target=feed, args=(0,))
    first.start()
    while first.is_alive():
        shared.counters()  # reads while the other thread processes without the GIL
        shared.segments()
    first.join()
    feed(1)
    np.testing.assert_array_equal(np.concatenate([results[0], results[1]]), alone)


def assert_same_figures(mine, theirs, where):
    """The same JSON value, numbers within rounding."""
    if isinstance(theirs, dict):
        assert set(mine) == set(theirs), where
        for key in theirs:
            assert_same_figures(mine[key], theirs[key], f"{where}.{key}")
    elif isinstance(theirs, list):
        assert len(mine) == len(theirs), where
        for i, (a, b) in enumerate(zip(mine, theirs)):
            assert_same_figures(a, b, f"{where}[{i}]")
    elif isinstance(theirs, float):
        assert mine == pytest.approx(theirs, abs=1e-12), where
    else:
        assert mine == theirs, where


def test_evaluate_gives_evldt_eval_figures(boxes, tmp_path):
    # The same numbers both ways: evldt-offline's CSV and evldt-sim's ground truth, read into numpy.
    path = recording(boxes, "evt3")
    truth_csv = boxes / "evt3" / "ground_truth.csv"
    run(OFFLINE, path, "-o", tmp_path / "segments.csv", "-q")
    run(EVAL, "--segments", tmp_path / "segments.csv", "--ground-truth", truth_csv, "--width", 240, "--height", 180,
        "--visible-only", "--json", tmp_path / "eval.json")
    (reference,) = json.loads((tmp_path / "eval.json").read_text())["runs"]
    rows = read_csv(tmp_path / "segments.csv")
    segments = np.zeros(len(rows), dtype=evldt.SEGMENT_DTYPE)
    segments["t"] = [int(r["t_us"]) for r in rows]
    segments["id"] = [int(r["id"]) for r in rows]
    for field in ("x0", "y0", "x1", "y1", "normal_velocity"):
        segments[field] = np.array([r[field] for r in rows], dtype=np.float32)
    truth_rows = read_csv(truth_csv)
    truth = np.zeros(len(truth_rows), dtype=evldt.GROUND_TRUTH_DTYPE)
    truth["t"] = [int(r["t_us"]) for r in truth_rows]
    truth["gt_id"] = [int(r["gt_id"]) for r in truth_rows]
    for field in ("x0", "y0", "x1", "y1"):
        truth[field] = [float(r[field]) for r in truth_rows]
    got = evldt.evaluate(segments, truth, 240, 180)
    assert len(got["accuracy"]) == 2
    assert 0.5 < got["accuracy"][0]["f"] < 1
    assert got["tracking"]["vel_rel_med"] is not None
    # One report: every figure of evldt-eval's run under the same key, besides the run's own fields.
    own = {"run", "fit_threshold", "events", "scene_seconds", "wall_seconds", "visible_only"}
    assert set(got) == set(reference) - own
    for key in got:
        assert_same_figures(got[key], reference[key], key)
    assert "visible_only" not in got
    # What an events-only camera can see, as evldt-eval --visible-only scores it.
    visible = evldt.evaluate(segments, truth, 240, 180, min_normal_speed=2)["visible_only"]
    theirs = reference["visible_only"]
    assert 0.5 < visible["visible_share"] <= 1
    assert_same_figures(visible, theirs, "visible_only")
    # The same run on a clock of Unix-epoch microseconds, as DV writes them: the same figures.
    epoch = 1_600_000_000_000_000
    segments["t"] += epoch
    truth["t"] += epoch
    shifted = evldt.evaluate(segments, truth, 240, 180)
    assert shifted == got


def test_a_calibration_straightens_the_lines_of_a_scene_seen_through_a_lens():
    lens = pathlib.Path(__file__).resolve().parents[2] / "tests/data/calibration/davis240c_camera_info.yaml"
    sim = evldt.simulate("boxes-6dof", duration_s=0.6, lens=str(lens))  # events in sensor pixels
    scores = {}
    for name, params in (("raw", {}), ("calibrated", {"calibration": str(lens)})):
        segments = evldt.Pipeline(sim.width, sim.height, **params).process(sim.events)
        scores[name] = evldt.evaluate(segments, sim.ground_truth, sim.width, sim.height)["accuracy"][0]["f"]
    assert scores["calibrated"] > 0.85 and scores["raw"] < scores["calibrated"] - 0.1, scores
    with pytest.raises(ValueError, match="calibration is of a 240x180 camera, the sensor 346x260"):
        evldt.Pipeline(346, 260, calibration=str(lens))


def test_simulated_ground_truth_equals_evldt_sim_csv(boxes):
    simulated = evldt.simulate("boxes-6dof", duration_s=0.4)
    expected = read_csv(boxes / "evt3" / "ground_truth.csv")
    assert len(simulated.ground_truth) == len(expected) > 100
    np.testing.assert_array_equal(simulated.ground_truth["t"], [int(r["t_us"]) for r in expected])
    np.testing.assert_array_equal(simulated.ground_truth["gt_id"], [int(r["gt_id"]) for r in expected])
    np.testing.assert_allclose(simulated.ground_truth["x0"], [float(r["x0"]) for r in expected], atol=1e-3)


def test_a_corrupt_recording_raises_the_message_evldt_offline_prints(boxes, tmp_path):
    data = bytearray(recording(boxes, "dat").read_bytes())
    broken = tmp_path / "broken.dat"
    broken.write_bytes(bytes(data[: len(data) // 2 + 3]))  # cut inside a record
    offline = run(OFFLINE, broken, "-o", tmp_path / "s.csv", "-q", "--summary-json", tmp_path / "s.json", check=False)
    assert offline.returncode == 2
    with pytest.raises(evldt.FormatError) as error:
        evldt.read(broken)
    assert str(error.value) in offline.stderr
    for chunk_events in (1000, 7777, 10**7):
        chunks = []
        with pytest.raises(evldt.FormatError):
            for chunk in evldt.read_chunks(broken, chunk_events=chunk_events):
                chunks.append(chunk)
        # Every event before the fault comes first: as many as evldt-offline read.
        assert sum(len(c) for c in chunks) == json.loads((tmp_path / "s.json").read_text())["events_read"] > 1000


def test_a_missing_file_raises_the_message_evldt_offline_prints(tmp_path):
    missing = tmp_path / "nothing.raw"
    offline = run(OFFLINE, "--format", "evt3", missing, check=False)
    assert offline.returncode == 1
    with pytest.raises(Exception) as error:
        evldt.read(missing, format="evt3")
    assert str(missing) in str(error.value)


def test_bad_parameters_and_events_raise_value_errors():
    with pytest.raises(ValueError, match="--fit-threshold"):
        evldt.Pipeline(640, 480, fit_threshold=3)
    with pytest.raises(ValueError, match="no_such_option|no-such-option"):
        evldt.Pipeline(640, 480, no_such_option=1)
    with pytest.raises(ValueError, match="sensor size"):
        evldt.Pipeline(0, 480)
    with pytest.raises(ValueError, match="scene"):
        evldt.simulate("no-such-scene")
    pipeline = evldt.Pipeline(640, 480)
    with pytest.raises(ValueError, match="x values"):
        pipeline.process(np.array([1, 2]), np.array([10, 70_000]), np.array([1, 1]), np.array([1, 1]))
    with pytest.raises(ValueError, match="one length"):
        pipeline.process(np.array([1, 2]), np.array([10]), np.array([1, 1]), np.array([1, 1]))
    with pytest.raises(ValueError, match="structured"):
        pipeline.process(np.zeros(3))
    with pytest.raises(ValueError):
        evldt.read(__file__, format="nonsense")


def test_events_off_the_sensor_or_back_in_time_are_counted_drops():
    pipeline = evldt.Pipeline(640, 480)
    events = np.zeros(4, dtype=evldt.EVENT_DTYPE)
    events["t"] = [100, 200, 50_000, 300]
    events["x"] = [10, 640, 20, 30]
    events["y"] = [10, 10, 479, 10]
    pipeline.process(events)
    counters = pipeline.counters()
    assert counters["events_accepted"] == 2
    assert counters["dropped_off_sensor"] == 1
    assert counters["dropped_back_in_time"] == 1


def test_message_types_round_trip():
    segments = evldt.segment_list_t()
    segment = evldt.line_segment_t()
    segment.id = 7
    segment.x0, segment.y0, segment.x1, segment.y1 = 1.5, 2.0, 30.0, 40.25
    segments.segments = [segment]
    segments.num_segments = 1
    decoded = evldt.segment_list_t.decode(segments.encode())
    assert decoded.num_segments == 1
    assert decoded.segments[0].id == 7 and decoded.segments[0].y1 == 40.25


@pytest.mark.skipif(not REAL.is_dir(), reason="../shared/real is absent: the real recordings are not here")
def test_real_recordings_read_as_evldt_offline_reads_them(tmp_path):
    checked = 0
    for path in sorted(REAL.iterdir()):
        if path.suffix not in (".raw", ".aedat4", ".h5", ".hdf5", ".dat") or path.stat().st_size > 200e6:
            continue
        summary = tmp_path / (path.name + ".json")
        offline = run(OFFLINE, path, "-o", tmp_path / "s.csv", "-q", "--summary-json", summary, check=False)
        if offline.returncode != 0:
            continue
        events = evldt.read(path).events
        assert len(events) == json.loads(summary.read_text())["events_read"], path.name
        checked += 1
    assert checked > 0


def test_lcm_log_reader_stops_with_a_format_error_on_a_cut_log(tmp_path):
    message = evldt.segment_list_t()
    message.source = "cam0"
    data = message.encode()
    record = struct.pack(">IqqII", 0xEDA1DA01, 0, 123, len("LINES_CAM0"), len(data)) + b"LINES_CAM0" + data
    log = tmp_path / "cut.lcm"
    log.write_bytes(record * 3 + record[:20])
    got = []
    with pytest.raises(evldt.FormatError, match="ends inside"):
        for channel, utime, payload in evldt.read_lcm_log(log):
            got.append(evldt.segment_list_t.decode(payload).source)
    assert got == ["cam0"] * 3
    log.write_bytes(record + b"garbage that is no record")
    with pytest.raises(evldt.FormatError, match="no record starts here|ends inside"):
        list(evldt.read_lcm_log(log))


def _write_pgm(path, image):
    path.write_bytes(b"P5 %d %d 255\n" % (image.shape[1], image.shape[0]) + image.tobytes())


def test_read_frames_gives_the_images_of_an_ecd_folder_and_names_a_bad_one(tmp_path):
    (tmp_path / "images").mkdir()
    first = np.arange(48 * 64, dtype=np.uint8).reshape(48, 64)
    second = np.full((48, 64), 200, dtype=np.uint8)
    _write_pgm(tmp_path / "images" / "a.pgm", first)
    _write_pgm(tmp_path / "images" / "b.pgm", second)
    (tmp_path / "images.txt").write_text("0.001 images/a.pgm\n0.0115 images/b.pgm\n")
    frames = evldt.read_frames(tmp_path, 64, 48)
    assert [t for t, _ in frames] == [1000, 11500]
    assert frames[0][1].dtype == np.uint8 and frames[0][1].shape == (48, 64)
    assert np.array_equal(frames[0][1], first) and np.array_equal(frames[1][1], second)
    with pytest.raises(evldt.FrameError, match="a.pgm is 64x48, the sensor 32x24"):
        evldt.read_frames(tmp_path, 32, 24)
    (tmp_path / "images.txt").write_text("0.001 images/a.pgm\n0.002 images/gone.pgm\n")
    with pytest.raises(ValueError, match="images.txt:2: frame .*gone.pgm is missing"):
        evldt.read_frames(tmp_path, 64, 48)


# --- live lines, received without the lcm Python module -----------------------------------
LINES = BUILD / "services/evldt-lines/evldt-lines"
CAMERA = BUILD / "services/evldt-camera/evldt-camera"
EXAMPLE = pathlib.Path(__file__).resolve().parents[2] / "libs/python/examples/subscribe_lines.py"
LIVE_URL = "udpm://239.255.76.67:7721?ttl=0"


@pytest.fixture()
def live_lines():
    """evldt-lines on loopback, ready; a function that runs the camera for 1 s of boxes-6dof."""
    lines = subprocess.Popen([str(LINES), "--lcm-url", LIVE_URL, "--log-period-s", "0"], stdout=subprocess.DEVNULL,
                             stderr=subprocess.PIPE, text=True)
    try:
        for line in lines.stderr:  # its log, until it is subscribed
            if "evldt-lines ready:" in line:
                break
        threading.Thread(target=lines.stderr.read, daemon=True).start()  # keep the pipe drained
        yield lambda: run(CAMERA, "--lcm-url", LIVE_URL, "--scene", "boxes-6dof", "--duration-s", "1", "-q")
    finally:
        lines.terminate()
        lines.wait(timeout=30)


def test_subscriber_receives_segments_and_whole_lines_as_arrays(live_lines):
    subscriber = evldt.Subscriber("cam0", LIVE_URL)
    camera = threading.Thread(target=live_lines)
    camera.start()
    received = []
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and (camera.is_alive() or len(received) < 40):
        lists = subscriber.receive(timeout_s=1)
        if lists is not None:
            received.append(lists)
    camera.join()
    segments = [lists for lists in received if not lists.whole_lines]
    whole = [lists for lists in received if lists.whole_lines]
    assert len(segments) > 20 and len(whole) > 20
    assert all(lists.camera == "cam0" and lists.lines.dtype == evldt.SEGMENT_DTYPE for lists in received)
    assert any(len(lists.lines) > 0 for lists in segments) and any(len(lists.lines) > 0 for lists in whole)
    times = [lists.t_us for lists in segments]
    assert times == sorted(times)
    lines = np.concatenate([lists.lines for lists in segments])
    assert ((lines["x0"] >= 0) & (lines["x0"] <= 240) & (lines["y1"] >= 0) & (lines["y1"] <= 180)).all()
    assert subscriber.undecodable == 0


def test_the_subscriber_example_prints_the_lines_it_receives(live_lines):
    example = subprocess.Popen([sys.executable, str(EXAMPLE), "cam0", LIVE_URL, "10"], stdout=subprocess.PIPE, text=True,
                               env=dict(os.environ))
    assert example.stdout.readline().startswith("ready: listening to camera cam0")
    live_lines()
    out, _ = example.communicate(timeout=60)
    assert example.returncode == 0
    assert "segments at event time" in out and "whole lines at event time" in out
    assert "  id " in out
