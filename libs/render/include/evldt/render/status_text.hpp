#pragma once
// Status text over a picture that fits it at every sensor size: fields ("t=1.234 s", "3.2 Mev/s")
// packed into lines as wide as the picture allows, drawn white on a dark outline.

#include <span>
#include <string>
#include <vector>

#include <opencv2/core.hpp>

namespace evldt {

/// The fields joined by two spaces into lines no wider than `width_px` in the status font, in order;
/// a field is never split (one wider than that stands alone on its line).
std::vector<std::string> wrap_fields(std::span<const std::string> fields, int width_px);
/// Draws `lines` from text row `row` down; returns the next free row.
int put_text_lines(cv::Mat& canvas, std::span<const std::string> lines, int row);

}  // namespace evldt
