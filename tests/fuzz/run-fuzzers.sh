#!/usr/bin/env bash
# Builds the libFuzzer targets with clang (ASan + UBSan) and fuzzes each for SECONDS, starting from
# its corpus in tests/fuzz/corpus/<target>/ (read only: new inputs go to out/fuzz/<target>/corpus,
# crash inputs to out/fuzz/<target>/). Prints executions, coverage and findings per target; exits 1
# if any target crashed. Usage: tests/fuzz/run-fuzzers.sh [SECONDS] [TARGET...]   (default 10 s, all)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
seconds=${1:-10}
shift || true
if ! command -v clang++ >/dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a >/dev/null 2>&1; then
  echo "run-fuzzers: needs clang and libFuzzer (apt-get install clang libclang-rt-14-dev)" >&2
  exit 1
fi
targets=("$@")
if ((${#targets[@]} == 0)); then
  targets=($(ls tests/fuzz/corpus))
fi
CC=clang CXX=clang++ cmake -S . -B build/fuzz -G Ninja -DEVLDT_SANITIZE=fuzzer >/dev/null
cmake --build build/fuzz -j "$(nproc)" --target "${targets[@]}"

crashed=0
printf '%-28s %10s %8s %6s %s\n' target executions exec/s cov result
for target in "${targets[@]}"; do
  out=out/fuzz/$target
  mkdir -p "$out/corpus"
  log=$out/fuzz.log
  # -rss_limit_mb: LCM's log reader callocs what a length field says (up to 2 GiB) before it
  # finds the bytes missing; that memory is never touched, so only the allocation limit is raised.
  if build/fuzz/tests/fuzz/$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2560 -malloc_limit_mb=2560 \
       -print_final_stats=1 -artifact_prefix="$out/" "$out/corpus" "tests/fuzz/corpus/$target" >"$log" 2>&1; then
    result=ok
  else
    result="CRASH: $(ls "$out"/crash-* "$out"/leak-* "$out"/timeout-* "$out"/oom-* 2>/dev/null | head -1 || true)"
    crashed=1
  fi
  execs=$(grep -oP 'stat::number_of_executed_units:\s*\K[0-9]+' "$log" || echo ?)
  rate=$(grep -oP 'stat::average_exec_per_sec:\s*\K[0-9]+' "$log" || echo ?)
  cov=$(grep -oP '#[0-9]+\s+\w+\s+cov: \K[0-9]+' "$log" | tail -1 || echo ?)
  printf '%-28s %10s %8s %6s %s\n' "$target" "$execs" "$rate" "${cov:-?}" "$result"
done
exit "$crashed"
