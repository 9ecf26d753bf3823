#include "common/host_ports.h"

#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <csignal>

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

// A socket of another process is on the host's count of its port but not on this process's.
TEST(SocketsOnPortTest, OwnSocketsAreThoseOfThisProcess) {
  BoundSocket mine(SOCK_DGRAM);
  EXPECT_EQ(OwnSocketsOnPort("udp", mine.port()), 1);
  int ports[2];  // the child's port, then its "done"
  ASSERT_EQ(pipe(ports), 0);
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0) {
    close(ports[0]);
    BoundSocket theirs(SOCK_DGRAM);
    const int port = theirs.port();
    if (write(ports[1], &port, sizeof(port)) != sizeof(port)) _exit(1);
    pause();  // until the parent kills it
    _exit(0);
  }
  close(ports[1]);
  int theirs = 0;
  const bool got = read(ports[0], &theirs, sizeof(theirs)) == sizeof(theirs);
  close(ports[0]);
  if (got) {
    EXPECT_EQ(SocketsOnPort("udp", theirs), 1);
    EXPECT_EQ(OwnSocketsOnPort("udp", theirs), 0);
  }
  kill(child, SIGKILL);
  waitpid(child, nullptr, 0);
  EXPECT_TRUE(got) << "the child did not say its port";
}

TEST(RunPortsTest, ARunsThreePortsAreInUseWhenAnyIsAndAPickAvoidsThem) {
  BoundSocket udp(SOCK_DGRAM);
  const int p = udp.port();
  // A run on p - 2, p - 1 or p would share the bound port; one on p + 1 would not (unless another
  // socket of this host happens to hold p + 1 .. p + 3).
  EXPECT_TRUE(RunPortsInUse(p));
  EXPECT_TRUE(RunPortsInUse(p - 1));
  EXPECT_TRUE(RunPortsInUse(p - 2));
  if (SocketsOnPort("udp", p + 1) + SocketsOnPort("udp", p + 2) + SocketsOnPort("udp", p + 3) ==
      0) {
    EXPECT_FALSE(RunPortsInUse(p + 1));
  }
  const int picked = PickRunPorts(10);
  ASSERT_NE(picked, 0) << "ten draws all in use";
  EXPECT_GE(picked, 20000);
  EXPECT_LT(picked + 2, 65536);
  EXPECT_EQ((picked - 20000) % 3, 0);
  const auto [low, high] = EphemeralPorts();
  EXPECT_TRUE(picked + 2 < low || picked > high)
      << picked << " overlaps the ephemeral ports " << low << "-" << high;
  EXPECT_FALSE(RunPortsInUse(picked));
}

}  // namespace
}  // namespace rl
