// Prints the lines a running evldt-lines publishes for one camera, through evldt's consumer SDK:
//   print_lines [CAMERA] [LCM_URL] [LISTS]     (cam0, LCM's default URL, 0: until Ctrl-C)
// A line per list ("segments" or "whole-lines", its event time and count), then a line per line.

#include <cstdio>
#include <cstdlib>
#include <string>

#include <evldt/client/line_subscriber.hpp>

int main(int argc, char** argv) {
  const std::string camera = argc > 1 ? argv[1] : "cam0";
  const std::string url = argc > 2 ? argv[2] : "";
  const long wanted = argc > 3 ? std::strtol(argv[3], nullptr, 10) : 0;
  lcm::LCM bus(url);
  if (!bus.good()) {
    std::fprintf(stderr, "print_lines: cannot open LCM at '%s'\n", url.c_str());
    return 1;
  }
  long lists = 0;
  evldt::client::LineSubscriber subscriber(bus, camera, [&](const evldt::client::LineList& list) {
    std::printf("%s %s t_us %lld lines %zu\n", list.whole_lines ? "whole-lines" : "segments", list.camera.c_str(),
                static_cast<long long>(list.t_us), list.lines.size());
    for (const evldt::client::Line& line : list.lines) {
      std::printf("  id %lld (%.1f, %.1f) - (%.1f, %.1f) score %.2f\n", static_cast<long long>(line.id), line.x0,
                  line.y0, line.x1, line.y1, line.score);
    }
    std::fflush(stdout);
    ++lists;
  });
  std::printf("ready: listening to camera %s\n", camera.c_str());
  std::fflush(stdout);
  while ((wanted == 0 || lists < wanted) && bus.handle() == 0) {
  }
  return 0;
}
