#include "common/host_ports.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

namespace rl {
namespace {

// A socket of `type` bound to a port the kernel picks on 127.0.0.1, listening if TCP; closed at
// the end of its scope.
class BoundSocket {
 public:
  explicit BoundSocket(int type) : fd_(socket(AF_INET, type, 0)) {
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    socklen_t size = sizeof(addr);
    if (fd_ < 0 || bind(fd_, reinterpret_cast<sockaddr*>(&addr), size) != 0 ||
        (type == SOCK_STREAM && listen(fd_, 1) != 0) ||
        getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &size) != 0) {
      ADD_FAILURE() << "cannot bind a socket";
      return;
    }
    port_ = ntohs(addr.sin_port);
  }
  ~BoundSocket() {
    if (fd_ >= 0) close(fd_);
  }
  BoundSocket(const BoundSocket&) = delete;
  BoundSocket& operator=(const BoundSocket&) = delete;
  int port() const { return port_; }

 private:
  int fd_;
  int port_ = 0;
};

TEST(SocketsOnPortTest, CountsTheSocketsOfAPortByProtocolAndState) {
  int udp_port = 0, tcp_port = 0;
  {
    BoundSocket udp(SOCK_DGRAM);
    BoundSocket tcp(SOCK_STREAM);
    udp_port = udp.port();
    tcp_port = tcp.port();
    EXPECT_EQ(SocketsOnPort("udp", udp_port), 1);
    EXPECT_EQ(SocketsOnPort("tcp", tcp_port), 1);
    EXPECT_EQ(SocketsOnPort("tcp", tcp_port, "0A"), 1);  // listening
    EXPECT_EQ(SocketsOnPort("tcp", tcp_port, "01"), 0);  // not established
  }
  EXPECT_EQ(SocketsOnPort("udp", udp_port), 0);
  EXPECT_EQ(SocketsOnPort("tcp", tcp_port, "0A"), 0);
}

}  // namespace
}  // namespace rl
