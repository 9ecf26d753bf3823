// The ports this host's sockets use: what the launcher checks before it picks a run's ports or
// waits for a hub to listen, and what the bus's tests check of the ports a process joins.
#pragma once

#include <string_view>

namespace rl {

/// How many of this host's sockets of `protocol` ("udp" or "tcp"; IPv4 and IPv6, from
/// /proc/net/<protocol> and /proc/net/<protocol>6) have the local port `port`, counting only those
/// in `state` unless it is empty (/proc's hex code: "0A" is a TCP socket listening).
int SocketsOnPort(std::string_view protocol, int port, std::string_view state = "");

/// Whether one of a run's three UDP ports (P, P + 1, P + 2: main, bulk, samples) is bound here.
bool RunPortsInUse(int port);

/// A run's three free UDP ports: P in [20000, 60000), a multiple of 3 from 20000 (so that two
/// picks never overlap), drawn at random up to `tries` times; 0 when every draw was in use.
int PickRunPorts(int tries);

}  // namespace rl
