// Fuzz target for the CSV readers (segment files that evldt-eval scores, ground-truth files of the
// simulator): the first input byte picks the reader. Checks: only std::runtime_error escapes, and
// every row read is finite.

#include <cmath>
#include <cstdint>
#include <stdexcept>

#include "evldt/pipeline/segment_csv.hpp"
#include "evldt/sim/ground_truth_csv.hpp"
#include "fuzz_support.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  using evldt::fuzz::require;
  const evldt::fuzz::TempFile file({data + 1, size - 1}, ".csv");
  try {
    if (data[0] % 2 == 0) {
      for (const evldt::SegmentRow& row : evldt::read_segment_csv(file.path())) {
        require(row.segment.q0.allFinite() && row.segment.q1.allFinite() && std::isfinite(row.score),
                "a non-finite segment row was read");
      }
    } else {
      for (const evldt::GroundTruthRow& row : evldt::read_ground_truth_csv(file.path())) {
        require(row.segment.a.allFinite() && row.segment.b.allFinite(), "a non-finite ground-truth row was read");
      }
    }
  } catch (const std::runtime_error&) {
    // Refused with the file and line named: the expected outcome for most inputs.
  }
  return 0;
}
