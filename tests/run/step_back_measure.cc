// Measures a step back as the app takes it (not a test: figures for docs/results.md): opens a
// project as the app does, paints N frames keeping a state every K frames within a budget
// (RunSnapshots, the app's defaults 10 and 1 GB), then steps back one frame (the nearest state
// at or before it restored, painted on from there) and, to compare, paints the same frames
// again from the state before the first frame (what a step back cost without the states, the
// project's opening and pre-pass aside, which it would have repeated too).
//   step_back_measure PROJECT.json [--frames N] [--every K] [--budget-mb MB] [--restores R]
//                     [--set K=V]...
// Prints the opening, painting and saving times, the states' count and memory, where the last
// state saved holds its bytes, the step back, the restore alone (the step back's state restored
// R times more, the median), the repaint from the first frame, and the peak resident memory.
#include <sys/resource.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "pipeline/core/project.h"
#include "pipeline/paint/painting_state.h"
#include "pipeline/run/paint_job.h"
#include "pipeline/run/paint_run.h"
#include "pipeline/run/run_snapshots.h"

namespace {

using Clock = std::chrono::steady_clock;
double Since(Clock::time_point start) {
  return std::chrono::duration<double>(Clock::now() - start).count();
}

// CPU seconds of this process so far, every thread (the machine may be shared: wall time
// alone would count the others' work).
double CpuSeconds() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_utime.tv_sec + usage.ru_stime.tv_sec +
         1e-6 * (usage.ru_utime.tv_usec + usage.ru_stime.tv_usec);
}

double PeakRssMb() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;
}

// The last state saved: its frame, bytes held alone and where they go; the largest saved.
struct LastSaved {
  int frames_read = -1;
  size_t bytes = 0;
  std::vector<fresco::PaintSession::State::Part> parts;
  size_t largest = 0;  // the largest state saved, alone
};

// Reads and paints until `frames` frames were read (or the capture ends); keeps states in
// `snapshots` when given, adding the time spent saving to `save_seconds` and the saves to
// `saves`, and each save's wall and CPU seconds to `save_walls` and `save_cpus` when given.
bool PaintUpTo(fresco::PaintRun* run, int frames, fresco::RunSnapshots* snapshots,
               double* save_seconds, int* saves, LastSaved* last = nullptr,
               std::vector<double>* save_walls = nullptr,
               std::vector<double>* save_cpus = nullptr) {
  while (run->stats().frames < frames) {
    if (snapshots && snapshots->Due(run->stats().frames)) {
      const Clock::time_point start = Clock::now();
      const double cpu = CpuSeconds();
      fresco::PaintRunState state;
      if (run->Save(&state)) {
        if (last) {
          *last = {run->stats().frames, state.bytes(), state.painting->parts, last->largest};
          last->largest = std::max(last->largest, state.bytes());
        }
        snapshots->Add(run->stats().frames, std::move(state)), ++*saves;
      }
      *save_seconds += Since(start);
      // The cost against the painting since the state before, as the app gives it (CPU).
      static double painted_since = -1;
      const double now = CpuSeconds();
      snapshots->Costs(now - cpu, painted_since < 0 ? 0 : cpu - painted_since);
      painted_since = now;
      if (save_walls) save_walls->push_back(Since(start));
      if (save_cpus) save_cpus->push_back(CpuSeconds() - cpu);
    }
    fresco::RunFrame frame;
    if (run->Next(&frame) != fresco::FrameRead::kFrame) return false;
    fresco::FrameReport report;
    if (frame.fate == fresco::FrameFate::kPaint) run->Paint(frame, &report);
  }
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr,
                 "usage: step_back_measure PROJECT.json [--frames N] [--every K] "
                 "[--budget-mb MB] [--restores R] [--set KEY=VALUE]...\n");
    return 2;
  }
  int frames = 200, every = 10, budget_mb = 1024, restores = 5;
  std::vector<std::string> overrides;
  for (int i = 2; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--frames") {
      frames = std::atoi(argv[i + 1]);
    } else if (flag == "--every") {
      every = std::atoi(argv[i + 1]);
    } else if (flag == "--budget-mb") {
      budget_mb = std::atoi(argv[i + 1]);
    } else if (flag == "--restores") {
      restores = std::max(1, std::atoi(argv[i + 1]));
    } else if (flag == "--set") {
      overrides.push_back(argv[i + 1]);
    } else {
      std::fprintf(stderr, "step_back_measure: unknown option %s\n", argv[i]);
      return 2;
    }
  }
  fresco::Project project;
  fresco::Status status = fresco::LoadProject(argv[1], overrides, &project);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 2;
  }
  Clock::time_point start = Clock::now();
  double cpu = CpuSeconds();
  fresco::PaintJobOptions job_options;
  job_options.read_frames_without_pose = true;  // as the app opens it
  std::unique_ptr<fresco::PaintJob> job;
  status = fresco::OpenPaintJob(project, job_options, &job);
  if (!status.ok()) {
    std::fprintf(stderr, "%s\n", status.message().c_str());
    return 1;
  }
  const double open_seconds = Since(start), open_cpu = CpuSeconds() - cpu;
  fresco::PaintRunOptions run_options;
  run_options.max_frames = project.pipeline.max_frames;
  auto run_owner =
      std::make_unique<fresco::PaintRun>(job->session.get(), job->source.get(), run_options);
  fresco::PaintRun& run = *run_owner;
  fresco::RunSnapshots snapshots(every, static_cast<size_t>(budget_mb) << 20);

  start = Clock::now();
  cpu = CpuSeconds();
  double save_seconds = 0;
  int saves = 0;
  LastSaved last;
  std::vector<double> save_walls, save_cpus;
  if (!PaintUpTo(&run, frames, &snapshots, &save_seconds, &saves, &last, &save_walls, &save_cpus))
    frames = run.stats().frames;
  const double paint_seconds = Since(start), paint_cpu = CpuSeconds() - cpu;

  // A step back from the last frame read: the nearest state at or before it, painted on.
  const int back_to = frames - 1;
  start = Clock::now();
  cpu = CpuSeconds();
  int from = -1;
  const fresco::PaintRunState* state = snapshots.AtOrBefore(back_to, &from);
  if (!state || !run.Restore(*state).ok()) {
    std::fprintf(stderr, "step_back_measure: no state to go back to\n");
    return 1;
  }
  const double restore_seconds = Since(start);
  double unused = 0;
  int none = 0;
  PaintUpTo(&run, back_to, nullptr, &unused, &none);
  const double step_back_seconds = Since(start), step_back_cpu = CpuSeconds() - cpu;

  // The restore alone, again and again (the median: the machine may be shared).
  std::vector<double> restore_walls, restore_cpus;
  for (int i = 0; i < restores; ++i) {
    start = Clock::now();
    cpu = CpuSeconds();
    if (!run.Restore(*state).ok()) return 1;
    restore_walls.push_back(Since(start)), restore_cpus.push_back(CpuSeconds() - cpu);
  }
  const auto median = [](std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v[v.size() / 2];
  };

  const size_t kept = snapshots.count(), kept_bytes = snapshots.bytes();
  const int spacing = snapshots.every();

  // The same frames painted again from the first: from the state before it when kept, else
  // (the app's only way then) the project opened again, its pre-pass too.
  start = Clock::now();
  cpu = CpuSeconds();
  int first = -1;
  const fresco::PaintRunState* initial = snapshots.AtOrBefore(0, &first);
  const bool reopened = initial == nullptr;
  if (initial) {
    if (!run.Restore(*initial).ok()) return 1;
    PaintUpTo(&run, back_to, nullptr, &unused, &none);
  } else {
    snapshots.Clear();
    run_owner.reset();
    job.reset();
    status = fresco::OpenPaintJob(project, job_options, &job);
    if (!status.ok()) return 1;
    fresco::PaintRun again(job->session.get(), job->source.get(), run_options);
    PaintUpTo(&again, back_to, nullptr, &unused, &none);
  }
  const double from_start_seconds = Since(start), from_start_cpu = CpuSeconds() - cpu;

  std::printf("project        %s\n", argv[1]);
  std::printf("opened in      %.2f s, %.2f s CPU (scene, buffers, whole-capture pre-pass)\n",
              open_seconds, open_cpu);
  std::printf(
      "painted        %d frames in %.2f s, %.2f s CPU; %.2f s of it saving states "
      "(%d saves, %.0f ms each)\n",
      frames, paint_seconds, paint_cpu, save_seconds, saves,
      1000 * save_seconds / std::max(1, saves));
  std::printf("each save      ");
  for (size_t i = 0; i < save_walls.size(); ++i)
    std::printf("%s%.2f s (%.2f s CPU)", i ? ", " : "", save_walls[i], save_cpus[i]);
  std::printf("\n");
  std::printf("states kept    %zu, every %d frames, %.0f MB (%.1f MB each; budget %d MB)\n", kept,
              spacing, kept_bytes / 1048576.0, kept_bytes / 1048576.0 / std::max<size_t>(1, kept),
              budget_mb);
  std::printf(
      "last state     before frame %d: %.0f MB alone, the largest saved %.0f MB (as held / "
      "before packing):\n",
      last.frames_read, last.bytes / 1048576.0, last.largest / 1048576.0);
  for (const fresco::PaintSession::State::Part& part : last.parts)
    if (part.raw > 0)
      std::printf("  %-18s %7.1f / %7.1f MB\n", part.what, part.held / 1048576.0,
                  part.raw / 1048576.0);
  std::printf(
      "step back      frame %d -> %d: %.3f s, %.3f s CPU (restore %.3f s, %d frames "
      "painted from the state at %d)\n",
      frames, back_to, step_back_seconds, step_back_cpu, restore_seconds, back_to - from, from);
  std::printf("restore alone  %.3f s, %.3f s CPU (median of %d; the state at %d, %.0f MB held)\n",
              median(restore_walls), median(restore_cpus), restores, from,
              state->bytes() / 1048576.0);
  std::printf(
      "from frame 0   %.2f s, %.2f s CPU to paint frames 0-%d again %s(%.1fx the step "
      "back's CPU)\n",
      from_start_seconds, from_start_cpu, back_to - 1,
      reopened ? "with the project opened again " : "from the state before them ",
      from_start_cpu / step_back_cpu);
  std::printf("peak RSS       %.0f MB\n", PeakRssMb());
  return 0;
}
