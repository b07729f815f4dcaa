// picture_colours PICTURE B G R TOLERANCE: prints "W H PIXELS NEAR DISTINCT" for a picture file: its
// size, the pixels within TOLERANCE of colour (B, G, R) in every channel, and the count of distinct
// colours (a blank picture has one or two). For the web view's browser test.
#include <cstdio>
#include <cstdlib>
#include <opencv2/imgcodecs.hpp>
#include <set>

int main(int argc, char** argv) {
  if (argc != 6) {
    std::fprintf(stderr, "usage: picture_colours PICTURE B G R TOLERANCE\n");
    return 2;
  }
  const cv::Mat picture = cv::imread(argv[1], cv::IMREAD_COLOR);
  if (picture.empty()) {
    std::fprintf(stderr, "picture_colours: cannot read %s as a picture\n", argv[1]);
    return 1;
  }
  const int b = std::atoi(argv[2]), g = std::atoi(argv[3]), r = std::atoi(argv[4]), tolerance = std::atoi(argv[5]);
  long near = 0;
  std::set<int> distinct;
  for (int y = 0; y < picture.rows; ++y) {
    for (int x = 0; x < picture.cols; ++x) {
      const cv::Vec3b p = picture.at<cv::Vec3b>(y, x);
      if (std::abs(p[0] - b) <= tolerance && std::abs(p[1] - g) <= tolerance && std::abs(p[2] - r) <= tolerance) ++near;
      distinct.insert(p[0] << 16 | p[1] << 8 | p[2]);
    }
  }
  std::printf("%d %d %ld %ld %zu\n", picture.cols, picture.rows, static_cast<long>(picture.total()), near,
              distinct.size());
  return 0;
}
