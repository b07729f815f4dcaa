#pragma once
// Short labels for line ids: a live service's ids are large (its start time is folded in), which
// written over the picture make it unreadable. Each id gets the next number in order of first
// appearance, and keeps it while it is seen (a re-associated id comes back under its old number).

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace evldt {

class ShortIds {
 public:
  /// Ids not seen for this many calls of label() are forgotten (their numbers are not reused).
  explicit ShortIds(std::uint64_t forget_after_calls = 300) : forget_after_(forget_after_calls) {}

  /// labels[i] = the short number of ids[i] (from 1). Forgets stale ids every forget_after calls,
  /// so the table holds only ids of the recent past.
  void label(std::span<const std::uint64_t> ids, std::vector<std::uint32_t>& labels);
  [[nodiscard]] std::size_t remembered() const { return numbers_.size(); }

 private:
  struct Entry {
    std::uint32_t number = 0;
    std::uint64_t last_call = 0;
  };
  std::uint64_t forget_after_;
  std::uint64_t calls_ = 0;
  std::uint32_t next_ = 1;
  std::unordered_map<std::uint64_t, Entry> numbers_;
};

}  // namespace evldt
