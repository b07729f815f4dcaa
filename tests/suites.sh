# The builds the test suite runs in, shared by tests/run.sh and tests/stress-run.sh (sourced from
# the source root): a Release build, AddressSanitizer + UndefinedBehaviorSanitizer, ThreadSanitizer.
suites=(release asan tsan)
jobs=$(nproc)

# LCM hands messages between threads through GLib, whose futex-based mutexes TSan cannot see:
# accesses made inside those uninstrumented libraries are not judged (our own code still is).
# TSan's default sleeps 1 s at exit while other threads (OpenCV's pool) live: the service tests
# time how fast a process stops, which that sleep would measure instead.
export TSAN_OPTIONS="halt_on_error=1 second_deadlock_stack=1 ignore_noninstrumented_modules=1 atexit_sleep_ms=0"

suite_cmake_args() {  # suite_cmake_args NAME
  case $1 in
    release) echo -DCMAKE_BUILD_TYPE=Release -DCMAKE_INSTALL_PREFIX=/usr -DEVLDT_WERROR=ON ;;  # the prefix of the Debian package it makes; warnings fail
    asan) echo -DEVLDT_SANITIZE=address ;;
    tsan) echo -DEVLDT_SANITIZE=thread ;;
    *) echo "unknown suite $1" >&2; return 1 ;;
  esac
}

# ccache (Debian's) keeps a rebuild of unchanged sources short, in this checkout or a fresh clone
# elsewhere: paths are hashed relative to the source root, without the build folder's.
export CCACHE_BASEDIR=$PWD CCACHE_NOHASHDIR=1
launcher=()
command -v ccache >/dev/null && launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache -DCMAKE_C_COMPILER_LAUNCHER=ccache)

build_suite() {  # build_suite NAME: configure and build build/NAME
  cmake -S . -B "build/$1" -G Ninja $(suite_cmake_args "$1") "${launcher[@]}" >/dev/null
  cmake --build "build/$1" -j "$jobs"
}

# What a suite leaves out (a ctest -E regex). ThreadSanitizer finds nothing in code that one thread
# runs, so the long single-threaded runs (the tools end to end, the noise filters and the simulator
# over whole scenes: 8 of TSan's 15 minutes) are left to Release and ASan + UBSan, which run them all.
suite_skips() {  # suite_skips NAME
  case $1 in
    tsan) echo '^(offline_cli|FusedChain\.|NoiseFilters\.|EventSimulator\.)' ;;
  esac
}

test_suite() {  # test_suite NAME [CTEST_ARGS...]: every test of build/NAME the suite runs
  local name=$1
  shift
  local skips
  skips=$(suite_skips "$name")
  local args=()
  if [[ -n $skips ]]; then args=(-E "$skips"); fi
  (cd "build/$name" && ctest --output-on-failure -j "$jobs" --timeout 900 "${args[@]}" "$@")
}
