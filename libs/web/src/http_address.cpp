#include "evldt/web/http_address.hpp"

#include <charconv>
#include <stdexcept>

namespace evldt {

HttpAddress parse_http_address(const std::string& text) {
  const auto fail = [&](const std::string& why) {
    return std::invalid_argument("HTTP address '" + text + "': " + why +
                                 " (expected [ADDR:]PORT, e.g. 8080 or 127.0.0.1:8080)");
  };
  HttpAddress address;
  const std::size_t colon = text.rfind(':');
  std::string port_text = text;
  if (colon != std::string::npos) {
    std::string host = text.substr(0, colon);
    if (host.size() >= 2 && host.front() == '[' && host.back() == ']')
      host = host.substr(1, host.size() - 2);  // [IPv6]
    if (!host.empty())
      address.host = host;
    else if (colon != 0)
      throw fail("no host");
    port_text = text.substr(colon + 1);
  }
  const char* const end = port_text.data() + port_text.size();
  const auto [stop, error] = std::from_chars(port_text.data(), end, address.port);
  if (port_text.empty() || error != std::errc() || stop != end) throw fail("no port number");
  if (address.port < 0 || address.port > 65535) throw fail("port outside 0..65535");
  return address;
}

}  // namespace evldt
