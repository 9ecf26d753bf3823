#include "common/host_ports.h"

#include <filesystem>
#include <fstream>
#include <random>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace rl {

namespace {

// The inodes of the sockets of `protocol` with the local port `port` (in `state` unless empty).
std::vector<std::string> SocketInodes(std::string_view protocol, int port, std::string_view state) {
  std::vector<std::string> inodes;
  for (const char* family : {"", "6"}) {
    std::ifstream in("/proc/net/" + std::string(protocol) + family);
    std::string line;
    std::getline(in, line);  // the header
    // "sl local_address rem_address st tx:rx tr:when retrnsmt uid timeout inode ...", each
    // address as HEXADDR:HEXPORT.
    while (std::getline(in, line)) {
      std::istringstream fields(line);
      std::string slot, local, remote, st, queues, timer, retransmits, uid, timeout, inode;
      if (!(fields >> slot >> local >> remote >> st >> queues >> timer >> retransmits >> uid >>
            timeout >> inode) ||
          (!state.empty() && st != state)) {
        continue;
      }
      const size_t colon = local.rfind(':');
      if (colon != std::string::npos && std::stoi(local.substr(colon + 1), nullptr, 16) == port) {
        inodes.push_back(inode);
      }
    }
  }
  return inodes;
}

}  // namespace

int SocketsOnPort(std::string_view protocol, int port, std::string_view state) {
  return static_cast<int>(SocketInodes(protocol, port, state).size());
}

int OwnSocketsOnPort(std::string_view protocol, int port) {
  std::set<std::string> own;  // "socket:[inode]" of this process's descriptors
  std::error_code error;
  for (const auto& fd : std::filesystem::directory_iterator("/proc/self/fd", error)) {
    std::error_code link_error;
    const std::string target = std::filesystem::read_symlink(fd.path(), link_error).string();
    if (!link_error && target.starts_with("socket:[")) own.insert(target);
  }
  int count = 0;
  for (const std::string& inode : SocketInodes(protocol, port, "")) {
    count += static_cast<int>(own.count("socket:[" + inode + "]"));
  }
  return count;
}

bool RunPortsInUse(int port) {
  return SocketsOnPort("udp", port) + SocketsOnPort("udp", port + 1) +
             SocketsOnPort("udp", port + 2) >
         0;
}

std::pair<int, int> EphemeralPorts() {
  std::ifstream in("/proc/sys/net/ipv4/ip_local_port_range");
  int low = 0, high = 0;
  if (in >> low >> high && 0 < low && low <= high && high < 65536) return {low, high};
  return {32768, 60999};  // Linux's default
}

int PickRunPorts(int tries) {
  const auto [low, high] = EphemeralPorts();
  std::vector<int> choices;
  for (int port = 20000; port + 2 < 65536; port += 3) {
    if (port + 2 < low || port > high) choices.push_back(port);
  }
  if (choices.empty()) return 0;
  std::random_device device;
  std::uniform_int_distribution<size_t> pick(0, choices.size() - 1);
  for (int attempt = 0; attempt < tries; ++attempt) {
    const int port = choices[pick(device)];
    if (!RunPortsInUse(port)) return port;
  }
  return 0;
}

}  // namespace rl
