#!/usr/bin/env bash
# End-to-end checks of the offline tools as a user runs them: help, bad usage, the simulator's files
# read back by every reader, determinism, and a truncated recording.
# Usage: offline_cli_test.sh BUILD_TOOLS_DIR SOURCE_DIR
set -euo pipefail
tools=$1
src=$2
sim=$tools/evldt-sim/evldt-sim
offline=$tools/evldt-offline/evldt-offline
eval=$tools/evldt-eval/evldt-eval
config=$tools/evldt-config/evldt-config
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

for bin in "$sim" "$offline" "$eval" "$config"; do
  "$bin" --help >"$work/help" || fail "$bin --help exit status"
  grep -q "Usage" "$work/help" || fail "$bin --help text"
  set +e
  "$bin" --no-such-flag >"$work/out" 2>&1
  status=$?
  set -e
  [[ $status -eq 1 ]] || fail "$bin --no-such-flag: exit status $status, not 1"
  grep -q "no-such-flag" "$work/out" || fail "$bin: unknown flag not named in the error"
done
echo "ok: --help and unknown flags"

# evldt-config prints a configuration that --config takes back, the same for a size as its shipped file.
"$config" --width 640 --height 480 >"$work/640.toml"
"$config" --config "$work/640.toml" | cmp -s - "$work/640.toml" || fail "evldt-config's TOML does not read back to itself"
for size in 240x180 346x260 640x480 1280x720; do  # the shipped files are evldt-config's defaults, byte for byte
  "$config" --width "${size%x*}" --height "${size#*x}" | cmp -s - "$src/config/$size.toml" ||
    fail "config/$size.toml is not what evldt-config writes for that size: regenerate it"
done
"$config" --width 640 --height 480 --block-size 10 | grep -qx "block-size = 10" || fail "evldt-config ignores a flag"
set +e
"$config" >"$work/out" 2>&1
status=$?
set -e
[[ $status -eq 1 ]] && grep -q "give the sensor size" "$work/out" || fail "evldt-config without a size: status $status"
echo "ok: evldt-config's TOML reads back to itself and is config/<size>.toml for every shipped size"

"$sim" --scene boxes-6dof --duration-s 0.4 --format evt3 --format ecd --format evt2 --format dat --out-dir "$work/rec" -q >"$work/sim.txt"
grep -q "events" "$work/sim.txt" || fail "simulator summary"
for f in events.raw events.txt events_evt2.raw events.dat ground_truth.csv; do [[ -s "$work/rec/$f" ]] || fail "missing $f"; done
echo "ok: simulator wrote every format and the ground truth"

run() { "$offline" "$@" -q --output-period-us 5000; }
run "$work/rec/events.raw" -o "$work/a.csv" >"$work/summary_a.txt"
run "$work/rec/events.raw" -o "$work/b.csv" >/dev/null
cmp -s "$work/a.csv" "$work/b.csv" || fail "two runs differ"
[[ $(wc -l <"$work/a.csv") -gt 100 ]] || fail "too few segment rows: $(wc -l <"$work/a.csv")"
head -1 "$work/a.csv" | grep -qx "t_us,id,x0,y0,x1,y1,score,status,normal_velocity,normal_velocity_std" || fail "CSV header"
echo "ok: two runs give byte-identical CSV ($(wc -l <"$work/a.csv") rows)"

# The same events through every reader, and straight from the simulator, give the same segments.
run "$work/rec/events.txt" --config "$src/config/240x180.toml" -o "$work/ecd.csv" >/dev/null
run "$work/rec/events_evt2.raw" -o "$work/evt2.csv" >/dev/null
run "$work/rec/events.dat" -o "$work/dat.csv" >/dev/null
run --scene boxes-6dof --duration-s 0.4 -o "$work/scene.csv" >/dev/null
for f in ecd evt2 dat scene; do cmp -s "$work/a.csv" "$work/$f.csv" || fail "$f run differs from the EVT3 run"; done
echo "ok: EVT3, ECD, EVT2, DAT and in-process simulation agree"

# ECD text has no geometry: without a size the tool must say so.
if "$offline" "$work/rec/events.txt" -o "$work/x.csv" -q >"$work/out" 2>&1; then fail "ECD without a size accepted"; fi
grep -q -- "--width" "$work/out" || fail "missing-size error does not say what to pass"
echo "ok: ECD text without a sensor size is refused with a hint"

# A truncated recording: the valid prefix is processed, the error names file and byte offset, exit 2.
size=$(stat -c %s "$work/rec/events_evt2.raw")
head -c $((size / 2 + 1)) "$work/rec/events_evt2.raw" >"$work/cut.raw"
set +e
"$offline" "$work/cut.raw" -o "$work/cut.csv" -q >"$work/cut_summary.txt" 2>"$work/cut_err.txt"
status=$?
set -e
[[ $status -eq 2 ]] || fail "truncated file exit status $status"
grep -q "cut.raw" "$work/cut_err.txt" && grep -q "byte" "$work/cut_err.txt" || fail "truncation error: $(cat "$work/cut_err.txt")"
[[ $(wc -l <"$work/cut.csv") -gt 10 ]] || fail "no segments from the valid prefix"
echo "ok: truncated recording -> exit 2, $(grep -o 'byte [0-9]*' "$work/cut_err.txt" | head -1), prefix processed"

# Rendering and the JSON summary.
"$offline" "$work/rec/events.raw" -o "$work/r.csv" -q --frames "$work/frames" --render-period-us 100000 --summary-json "$work/s.json" >/dev/null
ls "$work/frames"/frame_*.png >/dev/null 2>&1 || fail "no frames rendered"
grep -q '"lines_created"' "$work/s.json" || fail "summary JSON"
echo "ok: PNG frames and JSON summary"

# Evaluation: the ground truth scored against itself is perfect; a file run and an in-process run agree.
awk -F, 'NR == 1 { print "t_us,id,x0,y0,x1,y1,score,status"; next } { print $1 "," $2 "," $3 "," $4 "," $5 "," $6 ",1.0,good" }' \
  "$work/rec/ground_truth.csv" >"$work/gt_as_pred.csv"
"$eval" --segments "$work/gt_as_pred.csv" --ground-truth "$work/rec/ground_truth.csv" --width 240 --height 180 \
  --json "$work/self.json" >"$work/self.txt"
grep -Eq '^gt_as_pred.csv +- +1.000 +1.000 +1.000 +1.000 +1.000 +1.000' "$work/self.txt" || fail "self-evaluation: $(cat "$work/self.txt")"
# Tracking: every line covered by its own id all its life, no switch, IDF1 1; a CSV holds no velocity.
tail -1 "$work/self.txt" |
  awk '{ exit !($(NF - 5) == "1.000" && $(NF - 4) == "1.0" && $(NF - 3) == 0 && $(NF - 2) == "1.000" && $(NF - 1) == "n/a") }' ||
  fail "self-evaluation tracking: $(cat "$work/self.txt")"
"$offline" "$work/rec/events.raw" -o "$work/p.csv" -q --whole-lines "$work/whole.csv" >"$work/whole_summary.txt"
grep -q "whole lines .* ids, .* CSV rows" "$work/whole_summary.txt" || fail "whole lines in the summary: $(cat "$work/whole_summary.txt")"
# Whole lines join a true line's block segments under one id: identity F1 rises well above the segments'.
# The table's IDF1, before the two velocity columns (n/a: a CSV holds no velocity).
idf1_of() {
  "$eval" --segments "$1" --scene boxes-6dof --duration-s 0.4 --log-level warn | awk -v f="$(basename "$1")" '$1 == f { print $(NF - 2) }'
}
segment_idf1=$(idf1_of "$work/p.csv")
whole_idf1=$(idf1_of "$work/whole.csv")
awk -v s="$segment_idf1" -v w="$whole_idf1" 'BEGIN { exit !(w > 2 * s && w > 0.3) }' ||
  fail "whole lines' IDF1 $whole_idf1 is not well above the segments' $segment_idf1"
echo "ok: whole lines: IDF1 $whole_idf1 against the segments' $segment_idf1"
# Every column but the velocities, which a CSV does not hold.
"$eval" --segments "$work/p.csv" --scene boxes-6dof --duration-s 0.4 | awk '$1 == "p.csv" { $1 = ""; $2 = ""; NF -= 2; print }' >"$work/from_file.txt"
"$eval" --scene boxes-6dof --duration-s 0.4 --log-level warn --lifetime-png "$work/life.png" >"$work/in_process_both.txt"
awk '$1 == "boxes-6dof" && $2 != "whole" { $1 = ""; $2 = ""; NF -= 2; print }' "$work/in_process_both.txt" >"$work/in_process.txt"
# The CSV keeps coordinates to 1/1000 px, so P/R/F may differ in the third decimal; counts and lifetimes may not.
paste -d' ' "$work/from_file.txt" "$work/in_process.txt" | awk '{ n = NF / 2; for (i = 1; i <= n; ++i) {
    d = $i - $(i + n); if (d < 0) d = -d; if ((i <= 6 && d > 0.002) || (i > 6 && d != 0)) exit 1 } }' ||
  fail "file and in-process evaluation differ: $(cat "$work/from_file.txt") vs $(cat "$work/in_process.txt")"
[[ -s "$work/life.png" && -s "$work/life-whole.png" ]] || fail "no lifetime histograms"
# The whole lines evldt-offline wrote score as the in-process run's whole lines (IDF1 to 0.01).
in_process_whole_idf1=$(awk '$1 == "boxes-6dof" && $2 == "whole" { print $(NF - 2) }' "$work/in_process_both.txt")
awk -v a="$whole_idf1" -v b="$in_process_whole_idf1" 'BEGIN { d = a - b; exit !(d < 0.01 && d > -0.01) }' ||
  fail "whole lines from the file ($whole_idf1) and in process ($in_process_whole_idf1) differ"
echo "ok: evaluation of ground truth against itself is perfect; file and in-process scores agree: $(cat "$work/in_process.txt")"
# The whole lines' support by the segments (no ground truth needed): from the two CSVs as in process.
"$eval" --segments "$work/p.csv" --whole-lines "$work/whole.csv" --json "$work/support.json" >"$work/support.txt"
file_support=$(grep -oP 'support of whole.csv: \K[0-9.]+' "$work/support.txt")
in_process_support=$(grep -oP 'support of boxes-6dof whole: \K[0-9.]+' "$work/in_process_both.txt")
awk -v a="$file_support" -v b="$in_process_support" 'BEGIN { d = a - b; exit !(a > 0.5 && a <= 1 && d < 0.01 && d > -0.01) }' ||
  fail "whole-line support from the files ($file_support) and in process ($in_process_support) differ"
tr -d ' \n' <"$work/support.json" | grep -qP '"whole_line_support":\{"steps":4[01],"lines":[1-9]' ||
  fail "support JSON: $(cat "$work/support.json")"
"$eval" --whole-lines "$work/whole.csv" 2>"$work/support_alone.err" && fail "--whole-lines without --segments must fail"
grep -q "give --segments too" "$work/support_alone.err" || fail "--whole-lines alone: $(cat "$work/support_alone.err")"
echo "ok: whole-line support $file_support from the CSVs, $in_process_support in process"

# Recall per true edge: multi-speed's bars move sideways, so their horizontal edges run along their
# own motion and give no events; the vertical ones cross the sensor at 15 to 500 px/s.
"$eval" --scene multi-speed --duration-s 0.5 --log-level warn --edge-recall "$work/edges.csv" --edge-recall-png "$work/edges.png" \
  >"$work/edges.txt"
[[ -s "$work/edges.png" && -s "$work/edges-whole.png" ]] || fail "no edge-recall pictures"
grep -q "recall per true edge, multi-speed whole" "$work/edges.txt" || fail "no edge-recall tables: $(cat "$work/edges.txt")"
head -1 "$work/edges.csv" | grep -qx "run,t_us,gt_id,length_px,normal_speed_px_s,parallel_gap_px,pixels,matched" ||
  fail "edge-recall CSV header: $(head -1 "$work/edges.csv")"
awk -F, '$1 == "multi-speed whole" && $5 != "" { if ($5 < 2) { sp += $7; sm += $8 } else if ($5 >= 10) { mp += $7; mm += $8 } }
  END { printf "%.3f %.3f\n", sm / sp, mm / mp; exit !(sp > 0 && mp > 0 && mm / mp >= 0.8 && sm / sp <= 0.4) }' \
  "$work/edges.csv" >"$work/edges_recall.txt" || fail "edge recall of still / moving edges: $(cat "$work/edges_recall.txt")"
"$eval" --segments "$work/p.csv" --scene boxes-6dof --edge-recall "$work/no.csv" 2>"$work/edges_bad.err" &&
  fail "--edge-recall with --segments must fail"
grep -q "edge-recall scores the pipeline's run" "$work/edges_bad.err" || fail "--edge-recall with --segments: $(cat "$work/edges_bad.err")"
echo "ok: recall per true edge, still / moving across themselves: $(cat "$work/edges_recall.txt")"

# The overload model: every batch thinned to every 4th event, stored as evldt-lines stores it. It
# costs recall, not the run: F@1% stays within reach of the whole stream's (0.864 whole, 0.820 thinned).
"$eval" --scene monitor-hd --duration-s 0.15 --tolerance 0.01 --log-level warn >"$work/whole_stream.txt"
"$eval" --scene monitor-hd --duration-s 0.15 --tolerance 0.01 --log-level warn --thin 4 >"$work/thinned.txt"
whole_f=$(awk '$1 == "monitor-hd" && $2 != "whole" { print $5 }' "$work/whole_stream.txt")
thinned_f=$(awk '$1 == "monitor-hd" && $2 != "whole" { print $5 }' "$work/thinned.txt")
awk -v w="$whole_f" -v t="$thinned_f" 'BEGIN { exit !(w > 0 && t >= 0.75 && t < w) }' ||
  fail "--thin 4 must lose some F@1% and keep at least 0.75: whole $whole_f, thinned $thinned_f"
"$eval" --scene monitor-hd --duration-s 0.15 --thin 0 2>/dev/null && fail "--thin 0 must be refused"
echo "ok: overload model, F@1% whole stream $whole_f, every 4th event $thinned_f"

# Every ground-truth step counts: an empty prediction is no score, one step of prediction is
# charged for all the others, and the GT CSV and the scene give the same steps.
head -1 "$work/p.csv" >"$work/empty.csv"
"$eval" --segments "$work/empty.csv" --ground-truth "$work/rec/ground_truth.csv" --width 240 --height 180 >"$work/empty.txt"
grep -Eq '^empty.csv +- +n/a +0.000 +0.000 +n/a +0.000 +0.000 +0.0 +[0-9.]+ +41 +41 ' "$work/empty.txt" ||
  fail "an empty prediction must score P n/a, R 0, F 0 over all 41 steps: $(cat "$work/empty.txt")"
awk -F, 'NR == 1 || $1 == 200000' "$work/p.csv" >"$work/one_step.csv"
"$eval" --segments "$work/one_step.csv" --scene boxes-6dof --duration-s 0.4 --json "$work/one_step.json" >"$work/one_step.txt"
one_step_recall=$(grep -oP '"recall"\s*:\s*\K[0-9.]+' "$work/one_step.json" | head -1)
awk -v r="$one_step_recall" 'BEGIN { exit !(r > 0 && r < 0.1) }' || fail "one step of 41 must give recall < 0.1: $(cat "$work/one_step.txt")"
grep -q '"predicted_steps_scored": 1' "$work/one_step.json" || fail "one predicted step scored: $(cat "$work/one_step.json")"
"$eval" --segments "$work/p.csv" --ground-truth "$work/rec/ground_truth.csv" --width 240 --height 180 |
  awk '$1 == "p.csv" { $1 = ""; $2 = ""; NF -= 2; print }' >"$work/from_gt_csv.txt"
paste -d' ' "$work/from_file.txt" "$work/from_gt_csv.txt" | awk '{ n = NF / 2; for (i = 1; i <= n; ++i) {
    d = $i - $(i + n); if (d < 0) d = -d; if (d > 0.002) exit 1 } }' ||
  fail "GT CSV and scene scores differ: $(cat "$work/from_gt_csv.txt") vs $(cat "$work/from_file.txt")"
echo "ok: empty prediction -> P n/a, R 0, F 0; one step -> recall $one_step_recall over 41 steps; GT CSV and scene agree"
# Ground truth as the paper makes it: LSD on the simulator's frames, read back from the ECD layout.
"$sim" --scene three-lines-fast --duration-s 0.2 --frames-hz 100 --format ecd --out-dir "$work/frames" -q >/dev/null
[[ $(grep -c png "$work/frames/images.txt") -eq 21 ]] || fail "21 frames over 0.2 s at 100 Hz: $(wc -l <"$work/frames/images.txt")"
"$eval" --scene three-lines-fast --duration-s 0.2 --frames-gt "$work/frames" >"$work/frames.txt" 2>"$work/frames.err"
lsd_f=$(awk '$2 == "lsd/exact" { print $6 }' "$work/frames.txt")
awk -v f="$lsd_f" 'BEGIN { exit !(f > 0.9) }' || fail "LSD on the frames against the exact lines: $(cat "$work/frames.txt")"
grep -q "ground truth: LSD on 21 frames" "$work/frames.err" || fail "frames ground truth not announced: $(cat "$work/frames.err")"
# Frames as a real APS takes them: blurred over a 10 ms exposure, with read noise; LSD still finds the lines.
"$sim" --scene three-lines-fast --duration-s 0.2 --frames-hz 100 --frames-exposure-us 10000 --frames-noise 3 --format ecd \
  --out-dir "$work/frames_aps" -q >/dev/null
[[ -f "$work/frames_aps/images/frame_00000010.png" ]] || fail "no frame 10 with --frames-exposure-us"
cmp -s "$work/frames/images/frame_00000010.png" "$work/frames_aps/images/frame_00000010.png" && fail "--frames-exposure-us / --frames-noise changed nothing"
"$eval" --scene three-lines-fast --duration-s 0.2 --frames-gt "$work/frames_aps" >"$work/frames_aps.txt" 2>/dev/null
awk '$2 == "lsd/exact" { found = 1; if ($6 <= 0.9) exit 1 } END { exit !found }' "$work/frames_aps.txt" ||
  fail "LSD on blurred, noisy frames against the exact lines: $(cat "$work/frames_aps.txt")"
if "$sim" --scene three-lines-fast --frames-hz 100 --frames-exposure-us -1 --out-dir "$work/bad_aps" -q >/dev/null 2>&1; then
  fail "a negative exposure must be refused"
fi
# The same lines written out (--write-gt) score a segment file as the frames do; the paper's view per second.
"$offline" "$work/frames/events.txt" --width 640 --height 480 -q --output-period-us 10000 -o "$work/frames_seg.csv" >/dev/null
"$eval" --segments "$work/frames_seg.csv" --frames-gt "$work/frames" --width 640 --height 480 --write-gt "$work/lsd_gt.csv" \
  --per-second >"$work/by_frames.txt" 2>/dev/null
"$eval" --segments "$work/frames_seg.csv" --ground-truth "$work/lsd_gt.csv" --width 640 --height 480 >"$work/by_csv.txt" 2>/dev/null
[[ $(grep '^frames_seg.csv' "$work/by_frames.txt" | head -1) == $(grep '^frames_seg.csv' "$work/by_csv.txt") ]] ||
  fail "--write-gt CSV and --frames-gt score differently: $(cat "$work/by_frames.txt" "$work/by_csv.txt")"
grep -Eq '^frames_seg.csv +t0 0 s: +0-1 s 0\.[0-9]{3} / 0\.[0-9]{3}$' "$work/by_frames.txt" || fail "--per-second: $(cat "$work/by_frames.txt")"
# The same recording on a clock of Unix-epoch microseconds, as DV writes them: the same
# scores and the same per-second table, nothing allocated by the clock's value.
mkdir -p "$work/epoch"
shift_seconds() { awk -v OFS=' ' '{ split($1, t, "."); $1 = sprintf("%d.%s", t[1] + 1600000000, t[2]); print }' "$1"; }
shift_seconds "$work/frames/events.txt" >"$work/epoch/events.txt"
shift_seconds "$work/frames/images.txt" >"$work/epoch/images.txt"
ln -s "$work/frames/images" "$work/epoch/images"
"$offline" "$work/epoch/events.txt" --width 640 --height 480 -q --output-period-us 10000 -o "$work/epoch_seg.csv" >/dev/null
# (No --width/--height: the frames say the sensor's size.)
"$eval" --segments "$work/epoch_seg.csv" --frames-gt "$work/epoch" --per-second \
  >"$work/by_epoch_frames.txt" 2>"$work/by_epoch_frames.err" || fail "--frames-gt on an epoch clock: $(cat "$work/by_epoch_frames.err")"
same_run() { awk '{ if ($1 == "frames_seg.csv" || $1 == "epoch_seg.csv") $1 = "run"; if ($2 == "t0") $3 = "T0"; $1 = $1; print }' "$1"; }
diff <(same_run "$work/by_frames.txt") <(same_run "$work/by_epoch_frames.txt") >&2 ||
  fail "an epoch clock scores differently from a clock from 0 (above)"
grep -q "sensor 640x480: the size of the frames" "$work/by_epoch_frames.err" || fail "the sensor size not taken from the frames: $(cat "$work/by_epoch_frames.err")"
echo "ok: --frames-gt and --per-second on Unix-epoch time stamps score as on a clock from 0, the sensor size from the frames"
# --visible-only: multi-speed's rectangles slide sideways, so their top and bottom edges move along
# themselves and give no events; scored without them (and what lies on them), F rises.
"$eval" --scene multi-speed --duration-s 0.5 --visible-only --json "$work/visible.json" >"$work/visible.txt" 2>/dev/null ||
  fail "--visible-only on multi-speed"
python3 - "$work/visible.json" <<'PY' || fail "--visible-only: $(cat "$work/visible.txt")"
import json, sys
for run in json.load(open(sys.argv[1]))["runs"]:
    visible = run["visible_only"]
    assert visible["min_normal_speed"] == 2 and 0.5 < visible["visible_share"] < 0.8, visible
    assert visible["accuracy"][0]["f"] > run["accuracy"][0]["f"] + 0.05, (run["run"], visible, run["accuracy"])
PY
grep -Eq '^multi-speed whole visible +0\.[0-9]{3}( +0\.[0-9]{3}){6}$' "$work/visible.txt" || fail "--visible-only rows: $(cat "$work/visible.txt")"
# Against LSD on frames: a line is seen where the recording's events (here the folder's events.txt)
# fell along it around the frame's time.
"$eval" --segments "$work/frames_seg.csv" --frames-gt "$work/frames" --width 640 --height 480 --visible-only \
  >"$work/visible_frames.txt" 2>"$work/visible_frames.err" || fail "--visible-only with --frames-gt: $(cat "$work/visible_frames.err")"
grep -Eq "[0-9]+ of [0-9]+ LSD lines have events of .*frames/events.txt along them" "$work/visible_frames.err" ||
  fail "--visible-only, the LSD lines seen: $(cat "$work/visible_frames.err")"
grep -Eq '^frames_seg.csv visible +[01]\.[0-9]{3}( +[01]\.[0-9]{3}){6}$' "$work/visible_frames.txt" || fail "--visible-only rows on frames: $(cat "$work/visible_frames.txt")"
if "$eval" --scene three-lines-fast --duration-s 0.2 --frames-gt "$work/frames" --visible-only >/dev/null 2>"$work/visible_scene_frames.err"; then
  fail "--visible-only on a scene run against frames must be refused"
fi
grep -q "visible-only with --frames-gt scores a recording's --segments" "$work/visible_scene_frames.err" ||
  fail "--visible-only refusal: $(cat "$work/visible_scene_frames.err")"
echo "ok: --visible-only scores what an events-only camera can see beside the full score, on a scene and on frames"
# --overlay: a picture per scored frame, the predictions drawn over it (the same frames with no
# prediction give other pictures).
"$eval" --segments "$work/frames_seg.csv" --frames-gt "$work/frames" --overlay "$work/overlay" >/dev/null 2>&1 ||
  fail "--overlay failed"
[[ $(ls "$work/overlay" | grep -c '^step_[0-9]*\.png$') -eq 21 ]] || fail "--overlay: 21 pictures for 21 frames: $(ls "$work/overlay")"
[[ $(head -c 8 "$work/overlay/step_00010.png" | od -An -tx1 | tr -d ' ') == 89504e470d0a1a0a ]] || fail "--overlay wrote no PNG"
head -1 "$work/frames_seg.csv" >"$work/no_seg.csv"
"$eval" --segments "$work/no_seg.csv" --frames-gt "$work/frames" --overlay "$work/overlay_none" >/dev/null 2>&1
cmp -s "$work/overlay/step_00010.png" "$work/overlay_none/step_00010.png" && fail "--overlay drew no prediction"
if "$eval" --segments "$work/frames_seg.csv" --scene three-lines-fast --overlay "$work/overlay_bad" >/dev/null 2>&1; then
  fail "--overlay without --frames-gt must be refused"
fi
echo "ok: --overlay writes a picture per scored frame with the predictions drawn"
sed -i '5s/frame_00000004/frame_missing/' "$work/frames/images.txt"
set +e
"$eval" --scene three-lines-fast --duration-s 0.2 --frames-gt "$work/frames" >"$work/frames_bad.txt" 2>&1
status=$?
set -e
[[ $status -ne 0 ]] || fail "a missing frame must fail the run"
grep -q "images.txt:5: frame .*frame_missing.png is missing" "$work/frames_bad.txt" || fail "missing frame: $(cat "$work/frames_bad.txt")"
grep -q "WARN" "$work/frames_bad.txt" && fail "OpenCV's own warning leaked: $(cat "$work/frames_bad.txt")"
printf 'not frames' >"$work/junk.bin"
set +e
"$eval" --scene three-lines-fast --duration-s 0.2 --frames-gt "$work/junk.bin" >"$work/frames_junk.txt" 2>&1
status=$?
set -e
[[ $status -eq 1 ]] || fail "--frames-gt of a file that holds no frames must exit 1, got $status"
grep -q "junk.bin: not a source of frames evldt reads" "$work/frames_junk.txt" || fail "junk frames: $(cat "$work/frames_junk.txt")"
grep -Eq "WARN|ERROR:" "$work/frames_junk.txt" && fail "OpenCV's own messages leaked: $(cat "$work/frames_junk.txt")"
echo "ok: frames written at 100 Hz, LSD on them F@1% $lsd_f against the exact lines; a missing frame is named, a file of no frames refused"

# The paper's evaluation on a real DAVIS346 recording (AEDAT 4.0 from DV, Unix-epoch time stamps, APS
# frames): segments and whole lines scored against LSD on its frames, per second, with pictures.
real=$src/../shared/real/davis346_aestream_example.aedat4
if [[ -f $real ]]; then
  "$offline" "$real" -q -o "$work/real_seg.csv" --whole-lines "$work/real_whole.csv" >/dev/null 2>"$work/real_offline.err" ||
    fail "evldt-offline on $real: $(cat "$work/real_offline.err")"
  for run in seg whole; do
    "$eval" --segments "$work/real_$run.csv" --frames-gt "$real" --per-second --overlay "$work/real_overlay_$run" \
      >"$work/real_$run.txt" 2>"$work/real_$run.err" || fail "evldt-eval on $real: $(cat "$work/real_$run.err")"
    grep -q "sensor 346x260: the size of the frames" "$work/real_$run.err" || fail "sensor size of $real: $(cat "$work/real_$run.err")"
    grep -q "3 ground-truth steps scored" "$work/real_$run.err" || fail "3 frames of $real scored: $(cat "$work/real_$run.err")"
    awk -v run="real_$run.csv" '$1 == run && $2 == "-" { found = 1; if (!($5 > 0.1)) exit 1 } END { exit !found }' "$work/real_$run.txt" ||
      fail "F@1% of the $run on $real: $(cat "$work/real_$run.txt")"
    grep -qiw nan "$work/real_$run.txt" && fail "a nan in evldt-eval's tables on $real: $(cat "$work/real_$run.txt")"
    # Its first frame comes before any output: that second's precision is n/a, never nan.
    grep -Eq "^real_$run.csv +t0 1633953690 s: +0-1 s n/a / 0\.000 +1-2 s 0\.[0-9]{3} / 0\.[0-9]{3}$" "$work/real_$run.txt" ||
      fail "per second on $real: $(cat "$work/real_$run.txt")"
    [[ $(ls "$work/real_overlay_$run" | grep -c '\.png$') -eq 3 ]] || fail "3 pictures of $real"
    # What its events show: the LSD lines along which they fell within 10 ms of each frame.
    "$eval" --segments "$work/real_$run.csv" --frames-gt "$real" --visible-only --overlay "$work/real_visible_$run" \
      >"$work/real_visible_$run.txt" 2>"$work/real_visible_$run.err" || fail "--visible-only on $real: $(cat "$work/real_visible_$run.err")"
    grep -Eq "^real_$run.csv visible +0\.[0-9]{3}( +[01]\.[0-9]{3}){6}$" "$work/real_visible_$run.txt" ||
      fail "--visible-only on $real: $(cat "$work/real_visible_$run.txt")"
    cmp -s "$work/real_overlay_$run/step_00002.png" "$work/real_visible_$run/step_00002.png" &&
      fail "--visible-only drew the LSD lines without events as the others"
  done
  echo "ok: $real scored against LSD on its 3 frames, segments and whole lines, per second, with pictures"
else
  echo "skip: no real recordings at $src/../shared/real (../shared is absent)"
fi
# Calibrated lines: boxes-6dof seen through the DAVIS240C's lens (--lens: events in sensor pixels)
# scores far below the pinhole scene; with the calibration (any of its formats) as high as it.
calib=$src/tests/data/calibration
f_at_1() { awk '$1 == "boxes-6dof" && $2 != "whole" { print $5 }' "$1"; }
"$eval" --scene boxes-6dof --duration-s 0.8 --log-level warn >"$work/pinhole.txt"
"$eval" --scene boxes-6dof --duration-s 0.8 --lens "$calib/davis240c_calib.txt" --log-level warn >"$work/lens.txt"
"$eval" --scene boxes-6dof --duration-s 0.8 --lens "$calib/davis240c_calib.txt" --calibration "$calib/davis240c_camchain.yaml" \
  --log-level warn >"$work/calibrated.txt"
pinhole=$(f_at_1 "$work/pinhole.txt") lens=$(f_at_1 "$work/lens.txt") calibrated=$(f_at_1 "$work/calibrated.txt")
awk -v p="$pinhole" -v l="$lens" -v c="$calibrated" 'BEGIN { exit !(p > 0.8 && l < p - 0.1 && c > p - 0.02) }' ||
  fail "F@1% pinhole $pinhole, through the lens $lens, calibrated $calibrated"
"$offline" --scene boxes-6dof --duration-s 0.3 --lens "$calib/davis240c_calib.txt" --calibration "$calib/davis240c_opencv.xml" \
  -o "$work/calibrated.csv" >"$work/calibrated_summary.txt"
grep -Eq "calibration +.*davis240c_opencv.xml: [1-9][0-9]* events left out" "$work/calibrated_summary.txt" ||
  fail "the summary says what the calibration left out: $(cat "$work/calibrated_summary.txt")"
set +e
"$offline" --scene boxes-6dof --duration-s 0.1 --calibration "$calib/hd_equidistant_camchain.yaml" -o "$work/x.csv" >"$work/out" 2>&1
status=$?
set -e
[[ $status -eq 1 ]] && grep -q "calibration is of a 1280x720 camera, the sensor 240x180" "$work/out" ||
  fail "a calibration of another size: status $status, $(cat "$work/out")"
echo "ok: calibrated lines: F@1% $pinhole pinhole, $lens through the lens, $calibrated with the calibration"

echo "offline CLI: every check passed"
