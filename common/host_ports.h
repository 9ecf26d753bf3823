// The ports this host's sockets use: what the launcher checks before it picks a run's ports or
// waits for a hub to listen, and what the bus's tests check of the ports a process joins.
#pragma once

#include <string_view>

namespace rl {

/// How many of this host's sockets of `protocol` ("udp" or "tcp"; IPv4 and IPv6, from
/// /proc/net/<protocol> and /proc/net/<protocol>6) have the local port `port`, counting only those
/// in `state` unless it is empty (/proc's hex code: "0A" is a TCP socket listening).
int SocketsOnPort(std::string_view protocol, int port, std::string_view state = "");

}  // namespace rl
