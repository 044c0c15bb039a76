// A live feed of timestamped poses: TUM lines (`timestamp tx ty tz qx qy qz qw`, camera to
// world, seconds on the tracker's clock) read on a background thread from
//   tcp://HOST:PORT    Fresco connects to the tracker (and reconnects when it drops);
//   udp://HOST:PORT    Fresco listens on HOST:PORT, one or more lines per datagram;
//   fifo://PATH        a named pipe (mkfifo) the tracker writes to (reopened after EOF).
// Poses go into a PoseTrack; the painter asks for the pose at a time and waits (bounded) for
// the tracker to get there. A malformed line stops the feed with an error naming the
// address and the line ("tcp://127.0.0.1:9000:12: qw: not a number ('x')").
//
// When a tcp tracker drops the connection (or a fifo's writer closes it), the feed connects
// again with a bounded backoff: attempts start reconnect_interval_s apart and the interval
// doubles up to reconnect_max_interval_s; after reconnect_give_up_s without a connection the
// feed stops with an error naming the address. Each disconnection is reported as a gap: the
// tracker times of the last pose before it and the first after it (frames whose pose time
// falls between them get no pose when the gap exceeds PoseTrackOptions::max_gap_s), and the
// wall time without a connection.
#pragma once

#include <atomic>
#include <condition_variable>
#include <deque>
#include <limits>
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
  // Reconnect attempts start this far apart; the interval doubles up to the maximum.
  double reconnect_interval_s = 0.1;
  double reconnect_max_interval_s = 2.0;
  // No connection for this long (wall seconds) after a drop: the feed stops with an error.
  // 0: keep trying while the feed is open.
  double reconnect_give_up_s = 60.0;
  PoseTrackOptions track;
  bool keep_all = false;  // keep every pose received (for recording the session)
};

// One disconnection of a tcp or fifo feed.
struct PoseFeedGap {
  // Tracker times of the newest pose before the drop and of the first pose after the
  // reconnect; NaN when there is none (yet).
  double last_pose_before_s = std::numeric_limits<double>::quiet_NaN();
  double first_pose_after_s = std::numeric_limits<double>::quiet_NaN();
  double disconnected_s = 0;  // wall seconds without a connection (so far, while it lasts)
  int attempts = 0;           // connection attempts made during it
  bool reconnected = false;
  // The tracker time the gap spans (first after minus last before); NaN until both exist.
  double tracker_gap_s() const { return first_pose_after_s - last_pose_before_s; }
};

struct PoseFeedStats {
  long long poses = 0;        // pose lines received
  long long reconnects = 0;   // connections made after the first
  long long disconnects = 0;  // times the tracker went away
  bool connected = false;
  double seconds_since_last_pose = -1;  // -1 before the first
  double latest_time_s = 0;             // the newest sample's tracker time (0 before the first)
  double disconnected_s = 0;            // wall seconds without a connection, in all
  std::vector<PoseFeedGap> gaps;        // the last kMaxReportedGaps disconnections, in order
};

// PoseFeedStats::gaps holds at most this many (the oldest are forgotten).
constexpr size_t kMaxReportedGaps = 16;

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
  // Connects again (tcp) or reopens (fifo) with backoff; false when stopped or given up.
  bool ConnectWithBackoff();
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
  long long disconnects_ = 0;
  double disconnected_total_s_ = 0;    // closed gaps
  double disconnected_since_s_ = -1;   // wall time of the current drop (-1: connected)
  bool awaiting_first_after_ = false;  // the last gap wants its first pose after
  std::deque<PoseFeedGap> gaps_;
  bool connected_ = false;
  double last_pose_wall_s_ = -1;
};

}  // namespace fresco
