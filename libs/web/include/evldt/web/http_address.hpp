#pragma once
// Where a web view listens, as a user writes it: "8080", ":8080", "127.0.0.1:8080", "[::1]:8080".

#include <string>

namespace evldt {

struct HttpAddress {
  std::string host = "0.0.0.0";  ///< every interface, unless given
  int port = 0;                  ///< 0: any free port (the bound one is announced)
};

/// Parses "[ADDR:]PORT"; throws std::invalid_argument, naming the text, for anything else (a port
/// outside 0..65535, an empty host, no port).
HttpAddress parse_http_address(const std::string& text);

}  // namespace evldt
