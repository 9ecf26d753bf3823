// The ports this host's sockets use: what the launcher checks before it picks a run's ports or
// waits for a hub to listen, and what the bus's tests check of the ports a process joins.
#pragma once

#include <string_view>
#include <utility>

namespace rl {

/// How many of this host's sockets of `protocol` ("udp" or "tcp"; IPv4 and IPv6, from
/// /proc/net/<protocol> and /proc/net/<protocol>6) have the local port `port`, counting only those
/// in `state` unless it is empty (/proc's hex code: "0A" is a TCP socket listening).
int SocketsOnPort(std::string_view protocol, int port, std::string_view state = "");

/// The same, counting only the sockets this process holds open (those of other processes, say
/// tests running beside it that picked the same port, do not count).
int OwnSocketsOnPort(std::string_view protocol, int port);

/// Whether one of a run's three UDP ports (P, P + 1, P + 2: main, bulk, samples) is bound here.
bool RunPortsInUse(int port);

/// This host's ephemeral UDP and TCP ports, [low, high]: where the kernel binds a socket that
/// sends or connects without binding (/proc/sys/net/ipv4/ip_local_port_range; Linux's default
/// 32768-60999 when unreadable).
std::pair<int, int> EphemeralPorts();

/// A run's three free UDP ports: P, a multiple of 3 from 20000 (so that two picks never overlap)
/// with P .. P + 2 below 65536 and outside the ephemeral range, drawn at random up to `tries`
/// times; 0 when every draw was in use. Outside, because any sending socket (LCM's own, of this
/// run's processes or another's) may be given an ephemeral port, and one given a run's port would
/// keep the run's receivers from binding it.
int PickRunPorts(int tries);

}  // namespace rl
