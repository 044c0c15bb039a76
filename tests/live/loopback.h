// Loopback helpers for the live-source tests: a free port on 127.0.0.1 and TUM lines.
#pragma once

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <condition_variable>
#include <cstdio>
#include <cstring>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include <gtest/gtest.h>

#include "pipeline/core/rigid3.h"

namespace fresco::testing {

// A port on 127.0.0.1 nobody uses right now (SOCK_STREAM or SOCK_DGRAM).
inline int FreeLoopbackPort(int type) {
  const int fd = socket(AF_INET, type, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr);
  socklen_t len = sizeof addr;
  getsockname(fd, reinterpret_cast<sockaddr*>(&addr), &len);
  close(fd);
  return ntohs(addr.sin_port);
}

// A one-connection-at-a-time TCP server on 127.0.0.1 (ephemeral port) for pose feeds.
class PoseServer {
 public:
  // Listens on `port` (0: an ephemeral one). SO_REUSEADDR: a server can listen again on the
  // port of one that closed.
  explicit PoseServer(int port = 0) {
    // Close-on-exec: a `fresco` started by the test must not hold the port open.
    fd_ = socket(AF_INET, SOCK_STREAM | SOCK_CLOEXEC, 0);
    const int one = 1;
    setsockopt(fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
    sockaddr_in addr{};
    addr.sin_family = AF_INET;
    addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
    addr.sin_port = htons(port);
    EXPECT_EQ(bind(fd_, reinterpret_cast<sockaddr*>(&addr), sizeof addr), 0)
        << "port " << port << ": " << std::strerror(errno);
    socklen_t len = sizeof addr;
    getsockname(fd_, reinterpret_cast<sockaddr*>(&addr), &len);
    port_ = ntohs(addr.sin_port);
    listen(fd_, 4);
  }
  ~PoseServer() { Close(); }
  // Stops listening: connections are refused until a server listens on the port again.
  void Close() {
    if (fd_ >= 0) close(fd_);
    fd_ = -1;
  }
  int port() const { return port_; }
  std::string Address() const { return "tcp://127.0.0.1:" + std::to_string(port_); }
  // Waits for a connection; its socket (-1 on failure).
  int Accept() { return accept4(fd_, nullptr, nullptr, SOCK_CLOEXEC); }
  // Waits for a connection until `give_up()` says so (asked every 100 ms): -1 then. A test
  // that fails before its client connects must not hang in a destructor.
  template <class GiveUp>
  int AcceptUnless(const GiveUp& give_up) {
    for (;;) {
      pollfd p{fd_, POLLIN, 0};
      const int ready = poll(&p, 1, 100);
      if (ready > 0) return Accept();
      if (ready < 0 && errno != EINTR) return -1;
      if (give_up()) return -1;
    }
  }
  // Accepts one connection, sends `text`, closes it.
  void ServeOnce(const std::string& text) {
    const int c = Accept();
    ASSERT_GE(c, 0);
    EXPECT_EQ(send(c, text.data(), text.size(), MSG_NOSIGNAL), static_cast<ssize_t>(text.size()));
    close(c);
  }

 private:
  int fd_ = -1;
  int port_ = 0;
};

// A tracker that goes away mid-session: serves `before` to the first connection, then closes
// it and its listening socket (connections are refused), listens again on the same port
// `away_ms` later and serves `after` to the next connection, which stays open until the
// tracker is destroyed.
class DroppingTracker {
 public:
  DroppingTracker(std::string before, std::string after, int away_ms)
      : server_(std::make_unique<PoseServer>()), address_(server_->Address()) {
    thread_ = std::thread([this, before = std::move(before), after = std::move(after), away_ms] {
      const int port = server_->port();
      int c = server_->Accept();
      if (c < 0) return;
      send(c, before.data(), before.size(), MSG_NOSIGNAL);
      server_->Close();  // refused from now on (before the client sees the connection end)
      close(c);
      std::this_thread::sleep_for(std::chrono::milliseconds(away_ms));
      PoseServer again(port);
      c = again.AcceptUnless([this] {
        std::lock_guard<std::mutex> lock(mutex_);
        return done_;
      });
      if (c < 0) return;
      send(c, after.data(), after.size(), MSG_NOSIGNAL);
      std::unique_lock<std::mutex> lock(mutex_);
      done_cv_.wait_for(lock, std::chrono::seconds(120), [this] { return done_; });  // safety
      close(c);
    });
  }
  ~DroppingTracker() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
    }
    done_cv_.notify_all();
    thread_.join();
  }
  const std::string& Address() const { return address_; }

 private:
  std::unique_ptr<PoseServer> server_;
  std::string address_;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
  std::thread thread_;
};

// "timestamp tx ty tz qx qy qz qw\n" (camera to world), as a tracker sends it.
inline std::string TumLine(double t, const Rigid3d& world_from_cam) {
  const Eigen::Quaterniond& q = world_from_cam.rotation;
  const Eigen::Vector3d& p = world_from_cam.translation;
  char line[256];
  std::snprintf(line, sizeof line, "%.9f %.12f %.12f %.12f %.15f %.15f %.15f %.15f\n", t, p.x(),
                p.y(), p.z(), q.x(), q.y(), q.z(), q.w());
  return line;
}

}  // namespace fresco::testing
