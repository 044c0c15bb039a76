// Live sources, on loopback only: pose interpolation against exact motion, the
// bounded newest-wins queue, back-pressure under a source faster than the painter, pose
// feeds over TCP/UDP/named pipes (errors, reconnects), the time-offset estimation on a
// synthetic capture with a known offset, and the session recorder's staged frames.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <sys/stat.h>
#include <unistd.h>

#include <fcntl.h>
#include <algorithm>
#include <atomic>
#include <cmath>
#include <condition_variable>
#include <filesystem>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <gmock/gmock.h>
#include <gtest/gtest.h>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"
#include "pipeline/core/poses.h"
#include "pipeline/live/latest_queue.h"
#include "pipeline/live/live_frames.h"
#include "pipeline/live/pose_feed.h"
#include "pipeline/live/pose_track.h"
#include "pipeline/live/session_recorder.h"
#include "pipeline/live/time_offset_estimation.h"
#include "pipeline/run/offset_estimator.h"
#include "pipeline/synth/procedural_scenes.h"
#include "pipeline/synth/synthesize.h"
#include "tests/live/loopback.h"
#include "tests/paint/room_capture.h"
#include "tests/test_support.h"

namespace fresco {
namespace {

using ::testing::HasSubstr;
using ::testing::StartsWith;

constexpr double kDeg = M_PI / 180.0;

// A camera turning about a fixed axis at a constant rate and moving along a line at a
// constant speed: SLERP and linear interpolation are exact for it.
TimedPose Motion(double t) {
  const Eigen::Vector3d axis = Eigen::Vector3d(1, 2, 2).normalized();
  const double angle = 30.0 * kDeg * t;  // 30 deg/s
  TimedPose p;
  p.timestamp_s = t;
  p.world_from_cam = Rigid3d(Eigen::Quaterniond(Eigen::AngleAxisd(angle, axis)),
                             Eigen::Vector3d(1.0 + 0.5 * t, -2.0, 0.25 * t));
  return p;
}

double CentreError(const Rigid3d& cam_from_world, const TimedPose& truth) {
  return (cam_from_world.Centre() - truth.world_from_cam.translation).norm();
}

double AngleErrorDeg(const Rigid3d& cam_from_world, const TimedPose& truth) {
  return RotationDifferenceDeg(cam_from_world.Inverse().rotation, truth.world_from_cam.rotation);
}

TEST(PoseTrackTest, InterpolatesExactMotionBetweenSamples) {
  PoseTrack track;
  for (int i = 0; i <= 10; ++i) track.Add(Motion(0.1 * i));
  for (double t : {0.0, 0.025, 0.137, 0.5, 0.999, 1.0}) {
    Rigid3d pose;
    ASSERT_TRUE(track.At(t, &pose)) << t;
    EXPECT_LT(CentreError(pose, Motion(t)), 1e-12) << t;
    EXPECT_LT(AngleErrorDeg(pose, Motion(t)), 1e-6) << t;
  }
  // Numbers: half-way between 0.1 s (3 deg) and 0.2 s (6 deg) the camera has turned 4.5 deg
  // about the axis and its centre is at x = 1.075.
  Rigid3d pose;
  ASSERT_TRUE(track.At(0.15, &pose));
  EXPECT_NEAR(Eigen::AngleAxisd(pose.Inverse().rotation).angle() / kDeg, 4.5, 1e-9);
  EXPECT_NEAR(pose.Centre().x(), 1.075, 1e-12);
  EXPECT_NEAR(pose.Centre().z(), 0.0375, 1e-12);
}

TEST(PoseTrackTest, SlerpTakesTheShortWayAndMidpointsAreExact) {
  // 0 and 170 deg about z, the second stored as the negated quaternion.
  TimedPose a, b;
  a.timestamp_s = 0;
  b.timestamp_s = 1;
  b.world_from_cam.rotation =
      Eigen::Quaterniond(Eigen::AngleAxisd(170 * kDeg, Eigen::Vector3d::UnitZ()));
  b.world_from_cam.rotation.coeffs() *= -1;
  const Rigid3d mid = InterpolatePose(a, b, 0.5);
  const Eigen::AngleAxisd aa(mid.Inverse().rotation);
  EXPECT_NEAR(aa.angle() / kDeg, 85.0, 1e-9);
  EXPECT_NEAR(std::abs(aa.axis().z()), 1.0, 1e-12);
}

TEST(PoseTrackTest, OutOfOrderSamplesGapsAndEnds) {
  PoseTrackOptions options;
  options.max_gap_s = 0.25;
  options.max_extrapolate_s = 0.05;
  PoseTrack track(options);
  for (double t : {0.3, 0.1, 0.2, 0.0, 1.0, 1.1}) track.Add(Motion(t));  // gap 0.3 -> 1.0
  EXPECT_EQ(track.size(), 6u);
  EXPECT_EQ(track.first_time_s(), 0.0);
  EXPECT_EQ(track.last_time_s(), 1.1);
  Rigid3d pose;
  EXPECT_TRUE(track.At(0.25, &pose));
  EXPECT_LT(CentreError(pose, Motion(0.25)), 1e-12);
  EXPECT_FALSE(track.At(0.6, &pose)) << "inside the 0.7 s gap";
  EXPECT_TRUE(track.At(1.14, &pose)) << "within max_extrapolate_s after the end";
  EXPECT_LT(CentreError(pose, Motion(1.14)), 1e-12);  // constant motion extrapolates exactly
  EXPECT_LT(AngleErrorDeg(pose, Motion(1.14)), 1e-6);
  EXPECT_FALSE(track.At(1.2, &pose));
  EXPECT_FALSE(track.At(-0.1, &pose));
  track.Add(Motion(0.2));  // a sample at a time already held replaces it
  EXPECT_EQ(track.size(), 6u);
}

TEST(PoseTrackTest, MemoryIsBounded) {
  PoseTrackOptions options;
  options.max_samples = 50;
  PoseTrack track(options);
  for (int i = 0; i < 1000; ++i) track.Add(Motion(0.01 * i));
  EXPECT_EQ(track.size(), 50u);
  EXPECT_NEAR(track.first_time_s(), 9.5, 1e-9);
}

TEST(LatestQueueTest, NewestWinsAndDropsAreCounted) {
  LatestQueue<int> queue(3);
  for (int i = 0; i < 10; ++i) queue.Push(i);
  EXPECT_EQ(queue.dropped(), 7);
  EXPECT_EQ(queue.pushed(), 10);
  EXPECT_EQ(queue.high_water(), 3u);
  int v = -1;
  for (int expected : {7, 8, 9}) {
    ASSERT_TRUE(queue.Pop(&v, std::chrono::milliseconds(0)));
    EXPECT_EQ(v, expected);
  }
  EXPECT_FALSE(queue.Pop(&v, std::chrono::milliseconds(1)));
  queue.Close();
  EXPECT_FALSE(queue.Pop(&v));
}

// A live source that produces `count` 640x480 frames as fast as it can, then ends; it
// tells when it has produced them all.
class FastLiveSource : public VideoSource {
 public:
  explicit FastLiveSource(int count) : count_(count) {}
  bool Next(Frame* frame, Status*) override {
    if (next_ >= count_) {
      std::lock_guard<std::mutex> lock(mutex_);
      done_ = true;
      done_cv_.notify_all();
      return false;
    }
    frame->index = next_;
    frame->timestamp_s = next_ / 30.0;
    frame->bgr = cv::Mat(480, 640, CV_8UC3, cv::Scalar(next_ % 256, 0, 0));
    ++next_;
    return true;
  }
  int FrameCount() const override { return -1; }
  std::vector<std::string> FrameNames() const override { return {}; }
  double Fps() const override { return 30; }
  bool IsLive() const override { return true; }
  std::string Clock() const override { return "stream"; }
  void WaitDone() {
    std::unique_lock<std::mutex> lock(mutex_);
    done_cv_.wait(lock, [this] { return done_; });
  }

 private:
  int count_;
  int next_ = 0;
  std::mutex mutex_;
  std::condition_variable done_cv_;
  bool done_ = false;
};

TEST(LiveFramesTest, ASourceFasterThanThePainterIsDroppedNewestWins) {
  const int produced = 500;  // 460 MB if nothing were dropped
  auto source = std::make_unique<FastLiveSource>(produced);
  FastLiveSource* raw = source.get();
  LiveOptions options;
  options.queue_frames = 4;
  options.pose_wait_s = 0;
  PoseTrack track;
  for (int i = 0; i <= produced; ++i) track.Add(Motion(i / 30.0));
  LiveFrames frames(
      std::move(source), nullptr,
      [&](double t, double, Rigid3d* pose) { return track.At(t, pose); }, options, 0.0, nullptr);
  PosedFrame f;
  Status status;
  ASSERT_TRUE(frames.Next(&f, &status));  // the painter takes one frame, then is "slow":
  raw->WaitDone();                        // the source produces everything meanwhile
  std::vector<int> delivered = {f.frame.index};
  while (frames.Next(&f, &status)) {
    delivered.push_back(f.frame.index);
    EXPECT_TRUE(f.has_pose);
    EXPECT_LT(CentreError(f.cam_from_world, Motion(f.frame.timestamp_s)), 1e-9);
  }
  EXPECT_TRUE(status.ok()) << status.message();
  const LiveFramesStats stats = frames.stats();
  EXPECT_EQ(stats.frames_received, produced);
  EXPECT_LE(stats.queue_high_water, 4);  // memory bounded by the queue
  EXPECT_EQ(stats.frames_delivered + stats.frames_dropped, produced);
  // The painter got the first frame and the newest four.
  ASSERT_GE(delivered.size(), 5u);
  EXPECT_EQ(std::vector<int>(delivered.end() - 4, delivered.end()),
            (std::vector<int>{produced - 4, produced - 3, produced - 2, produced - 1}));
  EXPECT_GE(stats.frames_dropped, produced - 1 - 4 - 1);
  EXPECT_EQ(stats.end_reason, "the stream ended after 500 frames");  // the source said so
}

std::string TumLine(const TimedPose& p) {
  return testing::TumLine(p.timestamp_s, p.world_from_cam);
}

TEST(PoseFeedTest, TcpFeedInterpolatesAndReconnects) {
  testing::PoseServer server;
  std::string first = "# timestamp tx ty tz qx qy qz qw\n", second;
  for (int i = 0; i <= 10; ++i) first += TumLine(Motion(0.1 * i));
  for (int i = 11; i <= 20; ++i) second += TumLine(Motion(0.1 * i));
  std::thread tracker([&] {
    server.ServeOnce(first);   // the tracker drops the connection...
    server.ServeOnce(second);  // ...and comes back: Fresco reconnects
  });
  PoseFeedOptions options;
  options.keep_all = true;
  std::unique_ptr<PoseFeed> feed;
  const Status opened = PoseFeed::Open(server.Address(), options, &feed);
  ASSERT_TRUE(opened.ok()) << opened.message();
  Rigid3d pose;
  ASSERT_TRUE(feed->WaitPoseAt(1.55, 10.0, &pose));  // waits for the second connection
  EXPECT_LT(CentreError(pose, Motion(1.55)), 1e-9);
  EXPECT_LT(AngleErrorDeg(pose, Motion(1.55)), 1e-6);
  ASSERT_TRUE(feed->WaitPoseAt(2.0, 10.0, &pose));
  tracker.join();
  EXPECT_TRUE(feed->error().ok()) << feed->error().message();
  EXPECT_EQ(feed->stats().poses, 21);
  EXPECT_GE(feed->stats().reconnects, 1);
  EXPECT_EQ(feed->AllPoses().size(), 21u);
  EXPECT_FALSE(feed->WaitPoseAt(5.0, 0.05, &pose)) << "beyond the track";
}

// A file-like source (read on demand, nothing dropped) of tiny frames at given times.
class TimedFrameSource : public VideoSource {
 public:
  explicit TimedFrameSource(std::vector<double> times_s) : times_s_(std::move(times_s)) {}
  bool Next(Frame* frame, Status*) override {
    if (next_ >= times_s_.size()) return false;
    frame->index = static_cast<int>(next_);
    frame->timestamp_s = times_s_[next_++];
    frame->bgr = cv::Mat(8, 8, CV_8UC3, cv::Scalar(0, 0, 0));
    return true;
  }
  int FrameCount() const override { return static_cast<int>(times_s_.size()); }
  std::vector<std::string> FrameNames() const override { return {}; }
  double Fps() const override { return 10; }

 private:
  std::vector<double> times_s_;
  size_t next_ = 0;
};

// Mid-stream the tracker goes away (its connection and its listening socket close) and comes
// back on the same port 0.5 s later. The feed reconnects once, reports the gap (tracker time
// 1.0 s to 2.0 s), and frames after the gap are matched to the tracker's poses again.
TEST(PoseFeedTest, TrackerGoingAwayMidStreamIsReconnectedAndTheGapReported) {
  std::string before, after;
  for (int i = 0; i <= 10; ++i) before += TumLine(Motion(0.1 * i));  // 0 .. 1.0 s
  for (int i = 20; i <= 30; ++i) after += TumLine(Motion(0.1 * i));  // 2.0 .. 3.0 s
  testing::DroppingTracker tracker(before, after, 500);
  const std::string address = tracker.Address();
  PoseFeedOptions options;
  options.reconnect_interval_s = 0.05;
  options.reconnect_max_interval_s = 0.2;
  std::unique_ptr<PoseFeed> feed;
  const Status opened = PoseFeed::Open(address, options, &feed);
  ASSERT_TRUE(opened.ok()) << opened.message();

  // The painter's view: a frame every 0.1 s from 0 to 3 s, offset 0, poses from the feed.
  std::vector<double> times;
  for (int i = 0; i <= 30; ++i) times.push_back(0.1 * i);
  LiveOptions live;
  live.pose_wait_s = 20.0;  // a safety limit: frames wait for the tracker to come back
  LiveFrames frames(
      std::make_unique<TimedFrameSource>(times), nullptr,
      [&](double t, double timeout_s, Rigid3d* pose) {
        return feed->WaitPoseAt(t, timeout_s, pose);
      },
      live, 0.0, nullptr);
  PosedFrame f;
  Status status;
  std::vector<int> with_pose, without_pose;
  while (frames.Next(&f, &status)) {
    (f.has_pose ? with_pose : without_pose).push_back(f.frame.index);
    if (!f.has_pose) continue;
    EXPECT_LT(CentreError(f.cam_from_world, Motion(f.frame.timestamp_s)), 1e-9) << f.frame.index;
    EXPECT_LT(AngleErrorDeg(f.cam_from_world, Motion(f.frame.timestamp_s)), 1e-6);
  }
  EXPECT_TRUE(status.ok()) << status.message();
  // Frames 0..10 (before) and 20..30 (after the reconnect) have poses; 11..19 fall in the
  // 1 s gap (wider than max_gap_s, 0.5 s): none is interpolated across it.
  std::vector<int> expected_with, expected_without;
  for (int i = 0; i <= 30; ++i)
    (i <= 10 || i >= 20 ? expected_with : expected_without).push_back(i);
  EXPECT_EQ(with_pose, expected_with);
  EXPECT_EQ(without_pose, expected_without);
  EXPECT_EQ(frames.stats().frames_without_pose, 9);
  Rigid3d pose;
  ASSERT_TRUE(feed->WaitPoseAt(2.55, 1.0, &pose));
  EXPECT_LT(CentreError(pose, Motion(2.55)), 1e-9);

  const PoseFeedStats stats = feed->stats();  // before the tracker goes away again
  EXPECT_TRUE(feed->error().ok()) << feed->error().message();
  EXPECT_EQ(stats.reconnects, 1);
  EXPECT_EQ(stats.disconnects, 1);
  EXPECT_TRUE(stats.connected);
  EXPECT_EQ(stats.poses, 22);
  ASSERT_EQ(stats.gaps.size(), 1u);
  const PoseFeedGap& gap = stats.gaps[0];
  EXPECT_TRUE(gap.reconnected);
  EXPECT_NEAR(gap.last_pose_before_s, 1.0, 1e-9);
  EXPECT_NEAR(gap.first_pose_after_s, 2.0, 1e-9);
  EXPECT_NEAR(gap.tracker_gap_s(), 1.0, 1e-9);
  EXPECT_GT(gap.disconnected_s, 0.0);
  EXPECT_GE(gap.attempts, 2) << "refused at least once while the tracker was away";
  EXPECT_EQ(stats.disconnected_s, gap.disconnected_s);
  std::printf("reconnected after %d attempts, %.3f s disconnected; tracker gap %.3f s\n",
              gap.attempts, gap.disconnected_s, gap.tracker_gap_s());
}

// A tracker that never comes back: the backoff gives up after reconnect_give_up_s with an
// error naming the address, and a frame waiting for a pose is released by it.
TEST(PoseFeedTest, ATrackerThatNeverComesBackEndsTheFeedWithAnError) {
  auto server = std::make_unique<testing::PoseServer>();
  const std::string address = server->Address();
  std::thread tracker([&] {
    const int c = server->Accept();
    const std::string line = TumLine(Motion(0.0));
    send(c, line.data(), line.size(), MSG_NOSIGNAL);
    server->Close();
    close(c);
  });
  PoseFeedOptions options;
  options.reconnect_interval_s = 0.02;
  options.reconnect_max_interval_s = 0.1;
  options.reconnect_give_up_s = 0.3;
  std::unique_ptr<PoseFeed> feed;
  ASSERT_TRUE(PoseFeed::Open(address, options, &feed).ok());
  tracker.join();
  Rigid3d pose;
  EXPECT_FALSE(feed->WaitPoseAt(1.0, 30.0, &pose));  // returns once the feed gives up
  EXPECT_THAT(feed->error().message(),
              StartsWith(address + ": the tracker went away and did not come back within 0.3 s"));
  EXPECT_THAT(feed->error().message(), HasSubstr("Connection refused"));
  const PoseFeedStats stats = feed->stats();
  EXPECT_EQ(stats.reconnects, 0);
  EXPECT_EQ(stats.disconnects, 1);
  EXPECT_FALSE(stats.connected);
  ASSERT_EQ(stats.gaps.size(), 1u);
  EXPECT_FALSE(stats.gaps[0].reconnected);
  EXPECT_EQ(stats.gaps[0].last_pose_before_s, 0.0);
  EXPECT_TRUE(std::isnan(stats.gaps[0].first_pose_after_s));
  EXPECT_GE(stats.gaps[0].disconnected_s, 0.3);
  // Backoff: 0.02, 0.04, 0.08, 0.1, 0.1 ... apart: a handful of attempts, not hundreds.
  EXPECT_GE(stats.gaps[0].attempts, 2);
  EXPECT_LE(stats.gaps[0].attempts, 10);
}

TEST(PoseFeedTest, MalformedLineIsAnErrorNamingAddressAndLine) {
  testing::PoseServer server;
  std::thread tracker(
      [&] { server.ServeOnce(TumLine(Motion(0)) + TumLine(Motion(0.1)) + "0.2 1 2 3 0 0 0 x\n"); });
  std::unique_ptr<PoseFeed> feed;
  ASSERT_TRUE(PoseFeed::Open(server.Address(), PoseFeedOptions(), &feed).ok());
  tracker.join();
  Rigid3d pose;
  feed->WaitPoseAt(100.0, 10.0, &pose);  // returns once the feed fails
  EXPECT_THAT(feed->error().message(), StartsWith(server.Address() + ":3: qw: not a number"));
}

TEST(PoseFeedTest, UnreachableAndMalformedAddressesAreClearErrors) {
  PoseFeedOptions options;
  options.connect_timeout_s = 0.2;
  std::unique_ptr<PoseFeed> feed;
  const int port = testing::FreeLoopbackPort(SOCK_STREAM);  // nobody listens there
  const std::string address = "tcp://127.0.0.1:" + std::to_string(port);
  const Status refused = PoseFeed::Open(address, options, &feed);
  EXPECT_THAT(refused.message(), StartsWith(address + ": cannot connect: Connection refused"));
  EXPECT_THAT(PoseFeed::Open("tcp://127.0.0.1", options, &feed).message(),
              HasSubstr("not a pose feed"));
  EXPECT_THAT(PoseFeed::Open("fifo:///nonexistent/dir/poses", options, &feed).message(),
              StartsWith("fifo:///nonexistent/dir/poses: cannot open the named pipe"));
}

TEST(PoseFeedTest, UdpDatagramsAndNamedPipe) {
  // UDP: Fresco listens; each datagram carries lines.
  const int port = testing::FreeLoopbackPort(SOCK_DGRAM);
  std::unique_ptr<PoseFeed> feed;
  const std::string address = "udp://127.0.0.1:" + std::to_string(port);
  ASSERT_TRUE(PoseFeed::Open(address, PoseFeedOptions(), &feed).ok());
  const int sender = socket(AF_INET, SOCK_DGRAM, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_port = htons(port);
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  for (int i = 0; i <= 4; ++i) {
    std::string datagram = TumLine(Motion(0.1 * i));
    datagram.pop_back();  // the datagram ends the line
    sendto(sender, datagram.data(), datagram.size(), 0, reinterpret_cast<sockaddr*>(&to),
           sizeof to);
  }
  close(sender);
  Rigid3d pose;
  ASSERT_TRUE(feed->WaitPoseAt(0.4, 5.0, &pose));
  ASSERT_TRUE(feed->PoseAt(0.33, &pose));
  EXPECT_LT(CentreError(pose, Motion(0.33)), 1e-9);

  // Named pipe: the tracker opens it, writes, closes.
  const std::string fifo = testing::MakeTempDir("fifo") + "/poses";
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0);
  std::unique_ptr<PoseFeed> pipe_feed;
  ASSERT_TRUE(PoseFeed::Open("fifo://" + fifo, PoseFeedOptions(), &pipe_feed).ok());
  const int w = open(fifo.c_str(), O_WRONLY);
  ASSERT_GE(w, 0);
  std::string text;
  for (int i = 0; i <= 4; ++i) text += TumLine(Motion(0.1 * i));
  ASSERT_EQ(write(w, text.data(), text.size()), static_cast<ssize_t>(text.size()));
  close(w);
  ASSERT_TRUE(pipe_feed->WaitPoseAt(0.4, 5.0, &pose));
  EXPECT_LT(CentreError(pose, Motion(0.4)), 1e-9);
  EXPECT_EQ(pipe_feed->stats().poses, 5);
}

// The time-offset estimation on a synthetic hand-held capture whose tracker clock runs
// `offset` ahead of the video's.
// --record: frames are staged and swapped in whole by Finish; a recording that stops before
// Finish leaves the earlier one in DIR as it was, and nothing of its own.
TEST(SessionRecorderTest, FramesAppearOnlyWithFinishAndAStoppedRecordingLeavesTheEarlierOne) {
  namespace fs = std::filesystem;
  const std::string dir = testing::MakeTempDir("recorder") + "/rec";
  auto entries = [](const std::string& folder) {
    std::vector<std::string> names;
    for (const auto& e : fs::directory_iterator(folder)) names.push_back(e.path().filename());
    std::sort(names.begin(), names.end());
    return names;
  };
  ASSERT_TRUE(MakeDirectories(dir + "/frames").ok());
  testing::WriteText(dir + "/frames/old.png", "earlier recording");
  testing::WriteText(dir + "/project.json", "{}");
  Project project;
  project.scene = "/abs/scene.gltf";
  project.camera = "/abs/camera.cameramodel";
  Frame frame;
  frame.bgr = cv::Mat(4, 6, CV_8UC3, cv::Scalar(10, 20, 30));
  frame.bgr.at<cv::Vec3b>(1, 2) = cv::Vec3b(200, 100, 50);
  Rigid3d pose;
  pose.translation = Eigen::Vector3d(1, 2, 3);
  {
    SessionRecorder stopped;  // e.g. Ctrl-C: destroyed without Finish
    ASSERT_TRUE(stopped.Start(dir, project).ok());
    ASSERT_TRUE(stopped.Add(frame, pose).ok());
    EXPECT_EQ(entries(dir + "/frames"), std::vector<std::string>{"old.png"});
  }
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"frames", "project.json"}));
  EXPECT_EQ(entries(dir + "/frames"), std::vector<std::string>{"old.png"});

  SessionRecorder recorder;
  ASSERT_TRUE(recorder.Start(dir, project).ok());
  for (int i = 0; i < 2; ++i) {
    frame.timestamp_s = 0.5 * i;
    ASSERT_TRUE(recorder.Add(frame, pose).ok());
  }
  EXPECT_EQ(entries(dir + "/frames"), std::vector<std::string>{"old.png"});
  ASSERT_TRUE(recorder.Finish({Motion(0.0)}).ok());
  EXPECT_EQ(entries(dir), (std::vector<std::string>{"frames", "poses.txt", "project.json",
                                                    "tracker_poses.txt"}));
  EXPECT_EQ(entries(dir + "/frames"), (std::vector<std::string>{"000000.png", "000001.png"}));
  cv::Mat read;
  ASSERT_TRUE(ReadImage(dir + "/frames/000001.png", &read).ok());
  EXPECT_EQ(cv::norm(read, frame.bgr, cv::NORM_INF), 0.0);
  std::vector<PosedImage> poses;
  ASSERT_TRUE(ReadTumTrajectory(dir + "/poses.txt", &poses).ok());
  ASSERT_EQ(poses.size(), 2u);
  EXPECT_DOUBLE_EQ(poses[1].timestamp_s, 0.5);
  EXPECT_NEAR((poses[1].cam_from_world.translation - pose.translation).norm(), 0.0, 1e-9);
  std::string text;
  ASSERT_TRUE(ReadFileToString(dir + "/project.json", &text).ok());
  EXPECT_THAT(text, HasSubstr("\"frames/\""));
}

TEST(TimeOffsetTest, RecoversAKnownOffsetWithinAFramePeriod) {
  CubeRoomOptions room;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  SynthOptions o = testing::HandheldRoomCapture(40, 0.6);
  o.width = 160, o.height = 120, o.supersample = 1;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  const double fps = 30.0, offset = 0.2;
  PoseTrack track;
  for (size_t i = 0; i < capture.true_poses.size(); ++i)
    track.Add(TimedPose{i / fps + offset, capture.true_poses[i].cam_from_world.Inverse()});
  std::vector<Frame> frames;
  for (int i = 0; i < 40; ++i) {
    Frame f;
    f.index = i;
    f.timestamp_s = i / fps;
    f.bgr = capture.frames_bgr[i];
    Rigid3d unused;
    // Frames the track covers for every candidate (centre 0, +-0.35 s).
    if (track.At(f.timestamp_s - 0.35, &unused) && track.At(f.timestamp_s + 0.35, &unused))
      frames.push_back(f);
  }
  ASSERT_GE(frames.size(), 10u);
  PaintSessionInputs inputs;
  inputs.scene = &scene;
  inputs.pipeline = EstimationPipeline(PipelineOptions());
  inputs.typical_camera = &capture.camera;
  std::unique_ptr<PaintSession> session;
  ASSERT_TRUE(PaintSession::Create(inputs, &session).ok());
  TimeOffsetOptions options;
  options.centre_s = 0.0;
  options.search_s = 0.35;
  const auto pose_at = [&](double t, Rigid3d* pose) { return track.At(t, pose); };
  const TimeOffsetEstimate estimate =
      EstimateTimeOffset(frames, capture.camera, pose_at, options, session.get());
  ASSERT_TRUE(estimate.ok) << estimate.note;
  EXPECT_NEAR(estimate.offset_s, offset, 1.0 / fps);
  EXPECT_GT(estimate.contrast, 0.0);
  // Every offset is scored once: the fine scan's ends and centre are coarse candidates.
  for (size_t i = 0; i < estimate.candidates.size(); ++i)
    for (size_t j = 0; j < i; ++j)
      EXPECT_GT(std::abs(estimate.candidates[i].offset_s - estimate.candidates[j].offset_s),
                1e-9)
          << "offset " << estimate.candidates[i].offset_s << " scored twice";
  // The score at the true offset is lower than one frame period away.
  const TimeOffsetCandidate at_truth =
      ScoreTimeOffset(frames, capture.camera, pose_at, offset, session.get());
  const TimeOffsetCandidate off_by_two =
      ScoreTimeOffset(frames, capture.camera, pose_at, offset + 2 / fps, session.get());
  EXPECT_LT(at_truth.score, off_by_two.score);
  std::printf(
      "offset estimate %.4f s (truth %.3f, frame period %.4f s), %zu frames, %zu "
      "candidates, %.2f s; score at truth %.3f, +2 frames %.3f\n",
      estimate.offset_s, offset, 1 / fps, frames.size(), estimate.candidates.size(),
      estimate.seconds, at_truth.score, off_by_two.score);
}

// Offset tracking: the tracker's clock jumps 0.1 s ahead halfway through a hand-held capture
// (offset 0.2 s for frames 0..59, 0.3 s from frame 60 on), poses sent over TCP. The offset
// is estimated on the first window, then again every 15 frames over the last 30: once a
// window lies after the step, the offset in use follows it within one frame period; before
// the step, re-estimations agree with the offset in use and are not applied.
TEST(TimeOffsetTest, TrackingFollowsAStepInTheOffset) {
  CubeRoomOptions room;
  Scene scene;
  ASSERT_TRUE(MakeCubeRoomScene(room, &scene).ok());
  const int n = 120, step_at = 60;
  const double fps = 30.0, before = 0.2, after = 0.3, step_s = step_at / fps;
  SynthOptions o = testing::HandheldRoomCapture(n, 0.6);
  o.width = 160, o.height = 120, o.supersample = 1;
  SynthCapture capture;
  ASSERT_TRUE(SynthesizeCapture(scene, o, &capture).ok());
  std::string lines;
  for (int i = 0; i < n; ++i)
    lines += testing::TumLine(i / fps + (i < step_at ? before : after),
                              capture.true_poses[i].cam_from_world.Inverse());
  testing::PoseServer server;
  std::thread tracker([&] { server.ServeOnce(lines); });
  std::unique_ptr<PoseFeed> feed;
  ASSERT_TRUE(PoseFeed::Open(server.Address(), PoseFeedOptions(), &feed).ok());
  Rigid3d unused;
  ASSERT_TRUE(feed->WaitPoseAt((n - 1) / fps + after, 30.0, &unused));  // every pose is in
  tracker.join();

  // A file-like source: tracking waits for each re-estimation (reproducible).
  class CaptureSource : public VideoSource {
   public:
    explicit CaptureSource(const SynthCapture& c) : c_(c) {}
    bool Next(Frame* f, Status*) override {
      if (next_ >= c_.frames_bgr.size()) return false;
      f->index = static_cast<int>(next_);
      f->timestamp_s = next_ / 30.0;
      f->bgr = c_.frames_bgr[next_++];
      return true;
    }
    int FrameCount() const override { return static_cast<int>(c_.frames_bgr.size()); }
    std::vector<std::string> FrameNames() const override { return {}; }
    double Fps() const override { return 30; }

   private:
    const SynthCapture& c_;
    size_t next_ = 0;
  };
  LiveOptions live;
  live.pose_wait_s = 0;
  live.estimate_offset = true;
  live.offset_search_s = 0.35;
  live.offset_window_frames = 30;
  live.track_offset = true;
  live.offset_track_every_frames = 15;
  live.offset_track_search_s = 0.15;
  live.offset_track_min_gain = 0.1;
  LiveFrames frames(
      std::make_unique<CaptureSource>(capture), nullptr,
      [&](double t, double, Rigid3d* pose) { return feed->PoseAt(t, pose); }, live, 0.0,
      MakeTimeOffsetEstimator(&scene, capture.camera, PipelineOptions(), GroupingOptions(), 0.0,
                              TimeOffsetOptions()));
  PosedFrame f;
  Status status;
  std::vector<double> used(n, std::nan(""));  // the offset each frame was matched with
  while (frames.Next(&f, &status)) used[f.frame.index] = f.pose_time_s - f.frame.timestamp_s;
  ASSERT_TRUE(status.ok()) << status.message();
  const LiveFramesStats stats = frames.stats();
  ASSERT_TRUE(stats.offset_estimated) << stats.estimate.note;
  EXPECT_NEAR(stats.estimate.offset_s, before, 1.0 / fps);

  double follows_from_s = -1;  // end of the first window wholly after the step
  int applied_after = 0;
  for (const OffsetTrackPoint& p : stats.offset_track) {
    std::printf("window %.3f..%.3f s (%d frames): estimate %.4f s, score %.3f vs %.3f%s\n",
                p.window_start_s, p.time_s, p.frames, p.offset_s, p.score, p.current_score,
                p.applied ? " applied" : "");
    EXPECT_TRUE(p.ok);
    if (p.time_s < step_s) {  // wholly before the step
      EXPECT_NEAR(p.offset_s, before, 1.0 / fps);
      EXPECT_FALSE(p.applied) << "no better offset before the step";
    } else if (p.window_start_s >= step_s) {  // wholly after
      EXPECT_NEAR(p.offset_s, after, 1.0 / fps);
      if (follows_from_s < 0) follows_from_s = p.time_s;
    }
    if (p.applied) ++applied_after;
  }
  ASSERT_GE(stats.offset_track.size(), 5u);
  ASSERT_GT(follows_from_s, 0) << "no window after the step";
  EXPECT_GE(applied_after, 1);
  EXPECT_NEAR(stats.time_offset_s, after, 1.0 / fps);
  // Every frame before the step was matched at the first offset; every frame from the end of
  // the first window after the step on, at the new one.
  for (int i = 0; i < n; ++i) {
    if (!std::isfinite(used[i])) continue;  // no pose (beyond the track's end)
    if (i < step_at) {
      EXPECT_NEAR(used[i], before, 1.0 / fps) << "frame " << i;
    }
    if (i / fps >= follows_from_s) {
      EXPECT_NEAR(used[i], after, 1.0 / fps) << "frame " << i;
    }
  }
  std::printf("final offset %.4f s (truth %.3f), %zu re-estimations\n", stats.time_offset_s, after,
              stats.offset_track.size());
}

}  // namespace
}  // namespace fresco
