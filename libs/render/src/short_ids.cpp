#include "evldt/render/short_ids.hpp"

namespace evldt {

void ShortIds::label(std::span<const std::uint64_t> ids, std::vector<std::uint32_t>& labels) {
  ++calls_;
  labels.clear();
  for (const std::uint64_t id : ids) {
    const auto [it, inserted] = numbers_.try_emplace(id, Entry{next_, calls_});
    if (inserted) ++next_;
    it->second.last_call = calls_;
    labels.push_back(it->second.number);
  }
  if (calls_ % forget_after_ == 0) {
    std::erase_if(numbers_, [this](const auto& entry) { return calls_ - entry.second.last_call >= forget_after_; });
  }
}

}  // namespace evldt
