#include "common/host_ports.h"

#include <fstream>
#include <random>
#include <sstream>
#include <string>

namespace rl {

int SocketsOnPort(std::string_view protocol, int port, std::string_view state) {
  int count = 0;
  for (const char* family : {"", "6"}) {
    std::ifstream in("/proc/net/" + std::string(protocol) + family);
    std::string line;
    std::getline(in, line);  // the header
    // "slot local_address rem_address st ...", each address as HEXADDR:HEXPORT.
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, st;
      if (!(fields >> slot >> local >> remote >> st) || (!state.empty() && st != state)) continue;
      const size_t colon = local.rfind(':');
      if (colon != std::string::npos && std::stoi(local.substr(colon + 1), nullptr, 16) == port) {
        ++count;
      }
    }
  }
  return count;
}

bool RunPortsInUse(int port) {
  return SocketsOnPort("udp", port) + SocketsOnPort("udp", port + 1) +
             SocketsOnPort("udp", port + 2) >
         0;
}

int PickRunPorts(int tries) {
  std::random_device device;
  std::uniform_int_distribution<int> pick(0, 13332);
  for (int attempt = 0; attempt < tries; ++attempt) {
    const int port = 20000 + 3 * pick(device);
    if (!RunPortsInUse(port)) return port;
  }
  return 0;
}

}  // namespace rl
