#include "pipeline/live/pose_feed.h"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netdb.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <string_view>

#include "pipeline/core/poses.h"

namespace fresco {
namespace {

double NowS() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

std::string ErrnoText() { return std::strerror(errno); }

// A socket address for host:port (IPv4 or IPv6, first match); false with `error` set.
bool Resolve(const std::string& host, int port, int socktype, sockaddr_storage* addr,
             socklen_t* len, int* family, std::string* error) {
  addrinfo hints{};
  hints.ai_family = AF_UNSPEC;
  hints.ai_socktype = socktype;
  addrinfo* result = nullptr;
  const std::string service = std::to_string(port);
  const int rc = getaddrinfo(host.c_str(), service.c_str(), &hints, &result);
  if (rc != 0 || !result) {
    *error = std::string("cannot resolve host '") + host + "': " + gai_strerror(rc);
    return false;
  }
  std::memcpy(addr, result->ai_addr, result->ai_addrlen);
  *len = result->ai_addrlen;
  *family = result->ai_family;
  freeaddrinfo(result);
  return true;
}

// A non-blocking socket of `socktype` for host:port, and its address; -1 with `error` set.
int OpenSocket(const std::string& host, int port, int socktype, sockaddr_storage* addr,
               socklen_t* len, std::string* error) {
  int family = 0;
  if (!Resolve(host, port, socktype, addr, len, &family, error)) return -1;
  const int fd = socket(family, socktype | SOCK_CLOEXEC | SOCK_NONBLOCK, 0);
  if (fd < 0) *error = std::string("socket: ") + ErrnoText();
  return fd;
}

// Connects with a timeout; returns the fd or -1 with `error` set.
int ConnectTcp(const std::string& host, int port, double timeout_s, std::string* error) {
  sockaddr_storage addr{};
  socklen_t len = 0;
  const int fd = OpenSocket(host, port, SOCK_STREAM, &addr, &len, error);
  if (fd < 0) return -1;
  if (connect(fd, reinterpret_cast<sockaddr*>(&addr), len) == 0) return fd;
  if (errno != EINPROGRESS) {
    *error = std::string("cannot connect: ") + ErrnoText();
    close(fd);
    return -1;
  }
  pollfd p{fd, POLLOUT, 0};
  const int ready = poll(&p, 1, static_cast<int>(timeout_s * 1000));
  int so_error = 0;
  socklen_t so_len = sizeof so_error;
  if (ready <= 0) {
    *error = "cannot connect: no answer within " + std::to_string(timeout_s) + " s";
  } else if (getsockopt(fd, SOL_SOCKET, SO_ERROR, &so_error, &so_len) != 0 || so_error != 0) {
    *error = std::string("cannot connect: ") + std::strerror(so_error);
  } else {
    return fd;
  }
  close(fd);
  return -1;
}

int BindUdp(const std::string& host, int port, std::string* error) {
  sockaddr_storage addr{};
  socklen_t len = 0;
  const int fd = OpenSocket(host, port, SOCK_DGRAM, &addr, &len, error);
  if (fd < 0) return -1;
  const int one = 1;
  setsockopt(fd, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (bind(fd, reinterpret_cast<sockaddr*>(&addr), len) != 0) {
    *error = std::string("cannot listen: ") + ErrnoText();
    close(fd);
    return -1;
  }
  return fd;
}

}  // namespace

bool ParseHostPort(const std::string& address, const std::string& scheme, std::string* host,
                   int* port) {
  const std::string prefix = scheme + "://";
  if (address.rfind(prefix, 0) != 0) return false;
  std::string rest = address.substr(prefix.size());
  const size_t query = rest.find_first_of("?/");
  if (query != std::string::npos) rest = rest.substr(0, query);
  const size_t colon = rest.rfind(':');
  if (colon == std::string::npos || colon == 0 || colon + 1 >= rest.size()) return false;
  std::string h = rest.substr(0, colon);
  if (h.size() > 2 && h.front() == '[' && h.back() == ']') h = h.substr(1, h.size() - 2);
  const std::string p = rest.substr(colon + 1);
  if (p.find_first_not_of("0123456789") != std::string::npos || p.size() > 5) return false;
  const int value = std::stoi(p);
  if (value < 1 || value > 65535) return false;
  *host = h;
  *port = value;
  return true;
}

PoseFeed::PoseFeed(std::string address, PoseFeedOptions options)
    : address_(std::move(address)), options_(options), track_(options.track) {}

Status PoseFeed::Open(const std::string& address, const PoseFeedOptions& options,
                      std::unique_ptr<PoseFeed>* feed) {
  std::unique_ptr<PoseFeed> f(new PoseFeed(address, options));
  std::string error;
  if (address.rfind("fifo://", 0) == 0) {
    f->kind_ = 2;
    f->fifo_path_ = address.substr(7);
    // Non-blocking: opening a FIFO for reading does not wait for a writer.
    f->fd_ = open(f->fifo_path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    if (f->fd_ < 0) return Status::Error(address + ": cannot open the named pipe: " + ErrnoText());
  } else if (ParseHostPort(address, "tcp", &f->host_, &f->port_)) {
    f->kind_ = 0;
    const double deadline = NowS() + options.connect_timeout_s;
    do {  // the tracker may start a moment after Fresco
      f->fd_ = ConnectTcp(f->host_, f->port_, std::max(0.05, deadline - NowS()), &error);
      if (f->fd_ >= 0) break;
      std::this_thread::sleep_for(std::chrono::milliseconds(100));
    } while (NowS() < deadline);
    if (f->fd_ < 0) {
      return Status::Error(address + ": " + error + " (after trying for " +
                           std::to_string(options.connect_timeout_s).substr(0, 4) + " s)");
    }
  } else if (ParseHostPort(address, "udp", &f->host_, &f->port_)) {
    f->kind_ = 1;
    f->fd_ = BindUdp(f->host_, f->port_, &error);
    if (f->fd_ < 0) return Status::Error(address + ": " + error);
  } else {
    return Status::Error(address +
                         ": not a pose feed (expected tcp://HOST:PORT, udp://HOST:PORT or "
                         "fifo://PATH)");
  }
  f->connected_ = true;
  f->thread_ = std::thread([p = f.get()] { p->Run(); });
  *feed = std::move(f);
  return Status::Ok();
}

PoseFeed::~PoseFeed() {
  stop_ = true;
  if (thread_.joinable()) thread_.join();
  if (fd_ >= 0) close(fd_);
}

void PoseFeed::Fail(const Status& status) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (error_.ok()) error_ = status;
    connected_ = false;
  }
  changed_.notify_all();
}

bool PoseFeed::Reconnect() {
  if (fd_ >= 0) close(fd_);
  fd_ = -1;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    connected_ = false;
    partial_line_.clear();
    ++disconnects_;
    PoseFeedGap gap;
    if (!track_.empty()) gap.last_pose_before_s = track_.last_time_s();
    gaps_.push_back(gap);
    if (gaps_.size() > kMaxReportedGaps) gaps_.pop_front();
    disconnected_since_s_ = NowS();
    awaiting_first_after_ = false;
  }
  if (!options_.reconnect) {
    Fail(Status::Error(address_ + ": the tracker closed the connection"));
    return false;
  }
  return ConnectWithBackoff();
}

bool PoseFeed::ConnectWithBackoff() {
  double interval_s = std::max(0.01, options_.reconnect_interval_s);
  int attempts = 0;
  std::string error;
  while (!stop_) {
    ++attempts;
    if (kind_ == 2) {
      fd_ = open(fifo_path_.c_str(), O_RDONLY | O_NONBLOCK | O_CLOEXEC);
      if (fd_ < 0) error = "cannot open the named pipe: " + ErrnoText();
    } else {
      fd_ = ConnectTcp(host_, port_, std::min(interval_s, 1.0), &error);
    }
    const double now = NowS();
    std::unique_lock<std::mutex> lock(mutex_);
    PoseFeedGap& gap = gaps_.back();
    gap.attempts = attempts;
    gap.disconnected_s = now - disconnected_since_s_;
    if (fd_ >= 0) {
      gap.reconnected = true;
      disconnected_total_s_ += gap.disconnected_s;
      disconnected_since_s_ = -1;
      awaiting_first_after_ = true;
      connected_ = true;
      ++reconnects_;
      return true;
    }
    if (options_.reconnect_give_up_s > 0 && gap.disconnected_s >= options_.reconnect_give_up_s) {
      char text[160];
      std::snprintf(text, sizeof text,
                    ": the tracker went away and did not come back within %.1f s (%d attempts; "
                    "last: ",
                    options_.reconnect_give_up_s, attempts);
      disconnected_total_s_ += gap.disconnected_s;
      disconnected_since_s_ = -1;
      lock.unlock();
      Fail(Status::Error(address_ + text + error + ")"));
      return false;
    }
    lock.unlock();
    const double give_up_in_s = options_.reconnect_give_up_s > 0
                                    ? options_.reconnect_give_up_s - gap.disconnected_s
                                    : interval_s;
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(interval_s, give_up_in_s)));
    interval_s = std::min(2 * interval_s, std::max(options_.reconnect_max_interval_s, 0.01));
  }
  return false;
}

void PoseFeed::Run() {
  char buffer[65536];
  while (!stop_) {
    if (fd_ < 0 && !Reconnect()) return;
    pollfd p{fd_, POLLIN, 0};
    const int ready = poll(&p, 1, 100);
    if (ready < 0 && errno != EINTR) {
      Fail(Status::Error(address_ + ": poll: " + ErrnoText()));
      return;
    }
    if (ready <= 0) continue;
    const ssize_t n =
        kind_ == 1 ? recv(fd_, buffer, sizeof buffer, 0) : read(fd_, buffer, sizeof buffer);
    if (n > 0) {
      Consume(buffer, static_cast<size_t>(n), kind_ == 1);
      std::lock_guard<std::mutex> lock(mutex_);
      if (!error_.ok()) return;
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) continue;
    if (kind_ == 1) continue;  // UDP: nothing is ever "closed"
    // EOF (the tracker went away) or a read error: reconnect or stop.
    if (kind_ == 2) {  // a FIFO reports EOF until a writer opens it again: wait a little
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
    }
    if (!Reconnect()) return;
  }
}

void PoseFeed::Consume(const char* data, size_t size, bool datagram) {
  std::vector<std::string> lines;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    partial_line_.append(data, size);
    if (datagram && (partial_line_.empty() || partial_line_.back() != '\n'))
      partial_line_ += '\n';  // a datagram ends its last line
    size_t start = 0;
    for (size_t nl; (nl = partial_line_.find('\n', start)) != std::string::npos; start = nl + 1)
      lines.push_back(partial_line_.substr(start, nl - start));
    partial_line_.erase(0, start);
    if (partial_line_.size() > 4096) {
      error_ = Status::Error(address_ + ":" + std::to_string(line_number_ + 1) +
                             ": line longer than 4096 bytes (not TUM poses?)");
    }
  }
  for (const std::string& line : lines) {
    bool is_pose = false;
    TimedPose pose;
    const Status parsed = ParseTumLine(address_, ++line_number_, line, &is_pose, &pose.timestamp_s,
                                       &pose.world_from_cam);
    if (!parsed.ok()) {
      Fail(parsed);
      return;
    }
    if (!is_pose) continue;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      track_.Add(pose);
      if (options_.keep_all) all_.push_back(pose);
      if (awaiting_first_after_ && !gaps_.empty()) {
        gaps_.back().first_pose_after_s = pose.timestamp_s;
        awaiting_first_after_ = false;
      }
      ++poses_;
      last_pose_wall_s_ = NowS();
    }
    changed_.notify_all();
  }
}

bool PoseFeed::PoseAt(double t, Rigid3d* cam_from_world) const {
  std::lock_guard<std::mutex> lock(mutex_);
  return track_.At(t, cam_from_world);
}

bool PoseFeed::WaitPoseAt(double t, double timeout_s, Rigid3d* cam_from_world) {
  std::unique_lock<std::mutex> lock(mutex_);
  changed_.wait_for(lock, std::chrono::duration<double>(timeout_s),
                    [&] { return !error_.ok() || (!track_.empty() && track_.last_time_s() >= t); });
  return track_.At(t, cam_from_world);
}

Status PoseFeed::error() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return error_;
}

PoseFeedStats PoseFeed::stats() const {
  std::lock_guard<std::mutex> lock(mutex_);
  PoseFeedStats s;
  s.poses = poses_;
  s.reconnects = reconnects_;
  s.connected = connected_;
  s.seconds_since_last_pose = last_pose_wall_s_ < 0 ? -1 : NowS() - last_pose_wall_s_;
  s.latest_time_s = track_.empty() ? 0.0 : track_.last_time_s();
  s.disconnects = disconnects_;
  s.gaps.assign(gaps_.begin(), gaps_.end());
  s.disconnected_s = disconnected_total_s_;
  if (disconnected_since_s_ >= 0 && !s.gaps.empty()) {  // a drop that lasts
    s.gaps.back().disconnected_s = NowS() - disconnected_since_s_;
    s.disconnected_s += s.gaps.back().disconnected_s;
  }
  return s;
}

std::vector<TimedPose> PoseFeed::AllPoses() const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TimedPose> sorted = all_;
  std::stable_sort(sorted.begin(), sorted.end(), [](const TimedPose& a, const TimedPose& b) {
    return a.timestamp_s < b.timestamp_s;
  });
  return sorted;
}

std::vector<TimedPose> PoseFeed::PosesBetween(double from_s, double to_s) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<TimedPose> poses;
  for (const TimedPose& p : track_.samples())
    if (p.timestamp_s >= from_s && p.timestamp_s <= to_s) poses.push_back(p);
  return poses;
}

}  // namespace fresco
