// A live feed of timestamped poses: TUM lines (`timestamp tx ty tz qx qy qz qw`, camera to
// world, seconds on the tracker's clock) read on a background thread from
//   tcp://HOST:PORT    Fresco connects to the tracker (and reconnects when it drops);
//   udp://HOST:PORT    Fresco listens on HOST:PORT, one or more lines per datagram;
//   fifo://PATH        a named pipe (mkfifo) the tracker writes to (reopened after EOF).
// Poses go into a PoseTrack; the painter asks for the pose at a time and waits (bounded) for
// the tracker to get there. A malformed line stops the feed with an error naming the
// address and the line ("tcp://127.0.0.1:9000:12: qw: not a number ('x')").
#pragma once

#include <atomic>
#include <condition_variable>
#include <memory>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include "pipeline/core/status.h"
#include "pipeline/live/pose_track.h"

namespace fresco {

struct PoseFeedOptions {
  double connect_timeout_s = 5.0;  // tcp: the first connection must succeed within this
  bool reconnect = true;           // tcp/fifo: connect again when the tracker goes away
  double reconnect_interval_s = 0.2;
  PoseTrackOptions track;
  bool keep_all = false;  // keep every pose received (for recording the session)
};

struct PoseFeedStats {
  long long poses = 0;       // pose lines received
  long long reconnects = 0;  // connections made after the first
  bool connected = false;
  double seconds_since_last_pose = -1;  // -1 before the first
  double latest_time_s = 0;             // the newest sample's tracker time (0 before the first)
};

// Parses "tcp://HOST:PORT" / "udp://HOST:PORT" into host and port; false when malformed.
bool ParseHostPort(const std::string& address, const std::string& scheme, std::string* host,
                   int* port);

class PoseFeed {
 public:
  // Connects/binds/opens `address` and starts reading. Errors name the address ("tcp://
  // 127.0.0.1:9 : cannot connect: Connection refused").
  static Status Open(const std::string& address, const PoseFeedOptions& options,
                     std::unique_ptr<PoseFeed>* feed);
  ~PoseFeed();
  PoseFeed(const PoseFeed&) = delete;
  PoseFeed& operator=(const PoseFeed&) = delete;

  // The cam_from_world pose at tracker time `t`. Waits up to `timeout_s` for the track to
  // reach `t` (poses may arrive after the frame). False when there is none by then, when
  // `t` falls in a gap, or when the feed stopped with an error (see error()).
  bool WaitPoseAt(double t, double timeout_s, Rigid3d* cam_from_world);
  // Without waiting.
  bool PoseAt(double t, Rigid3d* cam_from_world) const;
  // The first error (malformed line, lost connection without reconnect); ok while running.
  Status error() const;
  PoseFeedStats stats() const;
  // Every pose received (options.keep_all), in time order.
  std::vector<TimedPose> AllPoses() const;
  // The samples the track still holds (the newest PoseTrackOptions::max_samples) between
  // tracker times `from_s` and `to_s`, in time order: the tracker's poses over a recording
  // without keep_all's unbounded memory.
  std::vector<TimedPose> PosesBetween(double from_s, double to_s) const;
  const std::string& address() const { return address_; }

 private:
  PoseFeed(std::string address, PoseFeedOptions options);
  void Run();
  bool Reconnect();
  void Consume(const char* data, size_t size, bool datagram);
  void Fail(const Status& status);

  std::string address_;
  PoseFeedOptions options_;
  int kind_ = 0;  // 0 tcp, 1 udp, 2 fifo
  std::string host_;
  int port_ = 0;
  std::string fifo_path_;
  int fd_ = -1;
  std::atomic<bool> stop_{false};
  std::thread thread_;

  mutable std::mutex mutex_;
  std::condition_variable changed_;
  PoseTrack track_;
  std::vector<TimedPose> all_;
  Status error_;
  std::string partial_line_;
  int line_number_ = 0;
  long long poses_ = 0;
  long long reconnects_ = 0;
  bool connected_ = false;
  double last_pose_wall_s_ = -1;
};

}  // namespace fresco
