#include "ui/gl/app_window.h"

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <GLFW/glfw3.h>
#include <imgui.h>
#include <imgui_impl_glfw.h>
#include <imgui_impl_opengl3.h>
#include <imgui_internal.h>
#include <nlohmann/json.hpp>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "pipeline/core/atomic_file.h"
#include "pipeline/core/image_io.h"
#include "ui/core/app_frame.h"
#include "ui/core/dropped_file.h"
#include "ui/core/input_queue.h"
#include "ui/core/layout_file.h"
#include "ui/core/ui_scale.h"
#include "ui/gl/gl.h"
#include "ui/gl/gl_textures.h"
#include "ui/gl/viewport_gl.h"
#include "ui/panels/panels.h"

namespace fresco {
namespace {

std::string ConfigDir() {
  if (const char* xdg = std::getenv("XDG_CONFIG_HOME"); xdg && *xdg)
    return std::string(xdg) + "/fresco";
  if (const char* home = std::getenv("HOME"); home && *home)
    return std::string(home) + "/.config/fresco";
  return "";
}

// The window's pixels (bottom-up in GL) as a top-down BGR image.
cv::Mat ReadWindow(int width, int height) {
  cv::Mat rgba(height, width, CV_8UC4);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadBuffer(GL_BACK);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data);
  cv::Mat flipped, bgr;
  cv::flip(rgba, flipped, 0);
  cv::cvtColor(flipped, bgr, cv::COLOR_RGBA2BGR);
  return bgr;
}

Status WritePanelList(const std::string& path, const std::vector<std::unique_ptr<Panel>>& panels) {
  nlohmann::json list = nlohmann::json::array();
  for (const auto& panel : panels) {
    ImGuiWindow* window = ImGui::FindWindowByName(PanelWindowId(panel->Title()).c_str());
    nlohmann::json entry = {{"title", panel->Title()}, {"open", panel->open}};
    if (const auto report = panel->Report(); !report.empty()) entry["state"] = report;
    if (window && panel->open) {
      entry["x"] = window->Pos.x;
      entry["y"] = window->Pos.y;
      entry["width"] = window->Size.x;
      entry["height"] = window->Size.y;
      entry["collapsed"] = window->Collapsed;
    }
    list.push_back(entry);
  }
  return WriteFileAtomic(path, nlohmann::json{{"panels", list}}.dump(2) + "\n");
}

// Opens the calibration panel on the folder; screenshots show the solved calibration.
void StartCalibration(const GuiOptions& options, CalibrationRunner* calibration,
                      std::vector<std::unique_ptr<Panel>>* panels) {
  calib::CalibrateRequest request;
  request.images_dir = options.calib_images;
  request.model = options.calib_model;
  if (Status s = calib::ParseBoardSpec(options.calib_board, "--board", &request.board); !s.ok()) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return;
  }
  for (auto& panel : *panels)
    if (std::string(panel->Title()) == kCalibrationPanelTitle) panel->open = true;
  calibration->Detect(request);
  if (options.screenshot.empty()) return;
  calibration->WaitIdle();
  calibration->Solve();
  calibration->WaitIdle();
}

// Opens the Poses panel and runs COLMAP on the project; screenshots show the finished run
// (and, for "bootstrap", the project using the bootstrapped poses).
void StartPoses(const GuiOptions& options, UiContext& ui,
                std::vector<std::unique_ptr<Panel>>* panels) {
  PosesRequest request;
  request.project = ui.state->project;
  request.out_dir =
      !options.poses_out.empty()
          ? options.poses_out
          : (std::filesystem::path(ui.state->project.file_path).parent_path() / "colmap-poses")
                .string();
  request.colmap.existing_model = options.poses_model;
  for (auto& panel : *panels)
    if (std::string(panel->Title()) == kPosesPanelTitle) panel->open = true;
  ui.poses->Run(request);
  if (options.screenshot.empty()) return;
  ui.poses->WaitIdle();
  if (options.poses != "bootstrap") return;
  // Asked for on the command line: applied, but not silently when likely worse.
  const PosesComparison& comparison = ui.poses->Snapshot()->bootstrap_comparison;
  if (comparison.better == "given" || comparison.better == "unknown")
    std::fprintf(stderr, "warning: applying the bootstrapped poses anyway: %s\n",
                 comparison.summary.c_str());
  if (Status s = ApplyBootstrappedPoses(*ui.poses->Snapshot(), ui.state); !s.ok()) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    return;
  }
  ui.runner->Restart(ui.state->project);
  ui.runner->Seek(std::max(0, options.frames - 1));
  ui.runner->WaitIdle();
}

// What the window's callbacks collect between frames (its user pointer).
struct WindowEvents {
  InputQueue input;
  std::vector<std::string> dropped;  // files dropped on the window, for DropPaths
};

WindowEvents* Events(GLFWwindow* window) {
  return static_cast<WindowEvents*>(glfwGetWindowUserPointer(window));
}

// GLFW's callbacks queue the keyboard and the mouse (input_queue.h) so that a tap or a
// drag shorter than a frame is still seen, and the files dropped on the window; focus,
// cursor enter and text go to ImGui's backend as before.
void InstallQueuedInput(GLFWwindow* window, WindowEvents* events) {
  glfwSetWindowUserPointer(window, events);
  glfwSetDropCallback(window, [](GLFWwindow* w, int count, const char** paths) {
    for (int i = 0; i < count; ++i) Events(w)->dropped.emplace_back(paths[i]);
  });
  glfwSetCursorPosCallback(window, [](GLFWwindow* w, double x, double y) {
    InputEvent e;
    e.kind = InputEvent::Kind::kMouseMove;
    e.x = static_cast<float>(x), e.y = static_cast<float>(y);
    Events(w)->input.Push(e);
  });
  glfwSetMouseButtonCallback(window, [](GLFWwindow* w, int button, int action, int) {
    InputEvent e;
    e.kind = InputEvent::Kind::kMouseButton;
    e.code = button;
    e.down = action == GLFW_PRESS;
    Events(w)->input.Push(e);
  });
  glfwSetScrollCallback(window, [](GLFWwindow* w, double dx, double dy) {
    InputEvent e;
    e.kind = InputEvent::Kind::kWheel;
    e.x = static_cast<float>(dx), e.y = static_cast<float>(dy);
    Events(w)->input.Push(e);
  });
  glfwSetKeyCallback(window, [](GLFWwindow* w, int key, int, int action, int) {
    if (action == GLFW_REPEAT) return;  // ImGui makes its own repeats from the held key
    InputEvent e;
    e.kind = InputEvent::Kind::kKey;
    e.code = key;
    e.down = action == GLFW_PRESS;
    Events(w)->input.Push(e);
  });
  glfwSetCursorEnterCallback(window, [](GLFWwindow* w, int entered) {
    ImGui_ImplGlfw_CursorEnterCallback(w, entered);
    if (entered) return;
    InputEvent e;  // the mouse left the window: nothing hovered
    e.kind = InputEvent::Kind::kMouseMove;
    e.x = e.y = -FLT_MAX;
    Events(w)->input.Push(e);
  });
  glfwSetWindowFocusCallback(window, ImGui_ImplGlfw_WindowFocusCallback);
  glfwSetCharCallback(window, [](GLFWwindow* w, unsigned int code_point) {
    InputEvent e;
    e.kind = InputEvent::Kind::kChar;
    e.code = static_cast<int>(code_point);
    Events(w)->input.Push(e);
  });
}

// Opens the project named on the command line. False when the app must exit (code 2): the
// project cannot be opened and either it names no missing file or the run is unattended.
bool OpenStartProject(const GuiOptions& options, AppState* state) {
  const bool screenshot = !options.screenshot.empty();
  if (!screenshot) {
    const std::string config = ConfigDir();
    if (!config.empty()) state->recent_file = config + "/recent.json";
    state->LoadRecent();
  }
  if (options.project.empty()) return true;
  if (Status s = state->Open(options.project); !s.ok()) {
    std::fprintf(stderr, "error: %s\n", s.message().c_str());
    // A file it names is missing: the app starts with the Project panel's path editor on
    // it. Unattended (a screenshot run) it exits as the command line does.
    if (!state->has_unopened || screenshot) return false;
    state->message = "error: " + s.message();
  }
  return true;
}

// On a high-density monitor the default size grows with its content scale (1600 x 1000 is
// 3200 x 2000 on a 4K screen at 192 dpi), within its work area.
void WindowSize(const GuiOptions& options, int* width, int* height) {
  *width = options.width, *height = options.height;
  if (options.size_given) return;
  GLFWmonitor* monitor = glfwGetPrimaryMonitor();
  if (!monitor) return;
  float scale_x = 1, scale_y = 1;
  glfwGetMonitorContentScale(monitor, &scale_x, &scale_y);
  int area_x = 0, area_y = 0, area_w = 0, area_h = 0;
  glfwGetMonitorWorkarea(monitor, &area_x, &area_y, &area_w, &area_h);
  const float scale = std::clamp(std::max(scale_x, scale_y), 1.0f, kMaxUiScale);
  *width = static_cast<int>(*width * scale), *height = static_cast<int>(*height * scale);
  if (area_w > 0 && area_h > 0)
    *width = std::min(*width, area_w), *height = std::min(*height, area_h);
}

// The app's OpenGL 3.3 window, made current; null (said on stderr) when there is none.
GLFWwindow* OpenWindow(const GuiOptions& options) {
  glfwSetErrorCallback([](int code, const char* text) {
    std::fprintf(stderr, "fresco gui: GLFW error %d: %s\n", code, text);
  });
  if (!glfwInit()) {
    std::fprintf(stderr, "fresco gui: cannot open a window (no display? run under xvfb-run)\n");
    return nullptr;
  }
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  int width = 0, height = 0;
  WindowSize(options, &width, &height);
  GLFWwindow* window = glfwCreateWindow(width, height, "Fresco", nullptr, nullptr);
  if (!window) {
    std::fprintf(stderr, "fresco gui: cannot create an OpenGL 3.3 window\n");
    glfwTerminate();
    return nullptr;
  }
  glfwMakeContextCurrent(window);
  glfwSwapInterval(options.screenshot.empty() ? 1 : 0);
  return window;
}

// ImGui's context and its GLFW and OpenGL backends, with the window's input queued into
// `events`.
void StartImGui(GLFWwindow* window, bool screenshot, WindowEvents* events) {
  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGuiIO& io = ImGui::GetIO();
  static std::string ini;
  if (screenshot || ConfigDir().empty()) {
    io.IniFilename = nullptr;  // screenshots always show the default layout
  } else {
    ini = ConfigDir() + "/imgui.ini";
    io.IniFilename = ini.c_str();
  }
  ImGui::StyleColorsDark();
  ConfigureImGui(&io);
  ImGui_ImplGlfw_InitForOpenGL(window, false);
  InstallQueuedInput(window, events);
  ImGui_ImplOpenGL3_Init("#version 330 core");
}

// The app while its window is open: the runners, the panels and what the frames share.
class GuiApp {
 public:
  GuiApp(const GuiOptions& options, GLFWwindow* window, WindowEvents* events, AppState* state)
      : options_(options),
        screenshot_(!options.screenshot.empty()),
        window_(window),
        events_(events),
        state_(*state),
        panels_(MakePanels()) {
    ui_.state = state;
    ui_.runner = &runner_;
    ui_.calibration = &calibration_;
    ui_.textures = &textures_;
    ui_.viewport = &viewport_;
    ui_.poses = &poses_;
  }

  // Draws frames until the user quits or the screenshot is taken; returns the exit code.
  int Run() {
    LoadLayout();
    StartWork();
    int code = 0;
    while (true) {
      int fb_width = 0, fb_height = 0;
      DrawFrame(&fb_width, &fb_height);
      ++frames_drawn_;
      // Screenshots: a few frames so that windows settle and textures are uploaded.
      if (screenshot_ && frames_drawn_ >= 4) {
        code = WriteScreenshot(fb_width, fb_height);
        break;
      }
      glfwSwapBuffers(window_);
      if (ui_.request_quit) break;
    }
    SaveLayout();
    return code;
  }

 private:
  // The splitters and font scale as the last session left them (not for screenshots,
  // which show the default layout).
  void LoadLayout() {
    layout_file_ = screenshot_ || ConfigDir().empty() ? "" : ConfigDir() + "/layout.json";
    if (layout_file_.empty()) return;
    if (Status s = LoadLayoutFile(layout_file_, &saved_); !s.ok())
      std::fprintf(stderr, "fresco gui: %s (the default layout instead)\n", s.message().c_str());
    ui_.layout = saved_.layout;
    ui_.scale.user = saved_.font_scale;
  }

  // The project's pipeline, and the calibration or pose run asked for on the command line.
  void StartWork() {
    if (state_.has_project) {
      runner_.Restart(state_.project);
      ui_.open_pending = true;  // a worker error then replaces "opened ..."
    }
    if (screenshot_ && state_.has_project) {
      runner_.Seek(std::max(0, options_.frames - 1));
      runner_.WaitIdle();
    }
    if (!options_.calib_images.empty()) StartCalibration(options_, &calibration_, &panels_);
    if (!options_.poses.empty() && state_.has_project) StartPoses(options_, ui_, &panels_);
  }

  // One frame: the window's events, the panels, and the drawing; the framebuffer's size.
  void DrawFrame(int* fb_width, int* fb_height) {
    ImGuiIO& io = ImGui::GetIO();
    glfwPollEvents();
    if (glfwWindowShouldClose(window_)) {
      glfwSetWindowShouldClose(window_, GLFW_FALSE);
      state_.pending_quit = true;
    }
    ui_.snapshot = runner_.Snapshot();
    DropPaths(ui_, events_->dropped);
    events_->dropped.clear();
    // The monitor's scale (it changes when the window moves to another monitor) and the
    // user's: fonts and style rebuilt between frames when they change; the first frame's
    // font texture is uploaded by the backend's first NewFrame.
    float scale_x = 1, scale_y = 1;
    glfwGetWindowContentScale(window_, &scale_x, &scale_y);
    ui_.scale.content = std::max(scale_x, scale_y);
    if (ApplyUiScale(ui_.scale.Total(), &ui_.scale_applied) && frames_drawn_ > 0) {
      ImGui_ImplOpenGL3_DestroyFontsTexture();
      ImGui_ImplOpenGL3_CreateFontsTexture();
    }
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    events_->input.NextFrame(&input_);  // this frame's share of the queued input
    CopyToImGui(input_, &io);
    if (screenshot_) io.MousePos = ImVec2(-FLT_MAX, -FLT_MAX);  // no hover effects in pictures
    ImGui::NewFrame();
    DrawAppFrame(ui_, panels_);
    ImGui::Render();
    glfwGetFramebufferSize(window_, fb_width, fb_height);
    glViewport(0, 0, *fb_width, *fb_height);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    textures_.EndFrame();
  }

  // The window's pixels and the panels' list; returns the exit code.
  int WriteScreenshot(int fb_width, int fb_height) {
    const cv::Mat pixels = ReadWindow(fb_width, fb_height);
    Status s = WriteImageAtomic(options_.screenshot, pixels);
    if (s.ok()) s = WritePanelList(options_.screenshot + ".json", panels_);
    if (!s.ok()) {
      std::fprintf(stderr, "error: %s\n", s.message().c_str());
      return 1;
    }
    std::fprintf(stderr, "fresco gui: wrote %s (%dx%d, frame %d)\n", options_.screenshot.c_str(),
                 fb_width, fb_height, ui_.snapshot->frame);
    return 0;
  }

  void SaveLayout() {
    if (layout_file_.empty()) return;
    saved_.layout = ui_.layout;
    saved_.font_scale = ui_.scale.user;
    if (Status s = SaveLayoutFile(layout_file_, saved_); !s.ok())
      std::fprintf(stderr, "fresco gui: %s\n", s.message().c_str());
  }

  const GuiOptions& options_;
  const bool screenshot_;
  GLFWwindow* const window_;
  WindowEvents* const events_;
  AppState& state_;
  InputState input_;
  int frames_drawn_ = 0;
  std::string layout_file_;
  SavedLayout saved_;
  PipelineRunner runner_;
  CalibrationRunner calibration_;
  PosesRunner poses_;
  GlTextures textures_{/*crisp_pixels=*/true};
  GlViewport viewport_;
  std::vector<std::unique_ptr<Panel>> panels_;
  UiContext ui_;
};

}  // namespace

int RunGuiApp(const GuiOptions& options) {
  AppState state;
  if (!OpenStartProject(options, &state)) return 2;
  GLFWwindow* window = OpenWindow(options);
  if (!window) return 1;
  WindowEvents events;
  StartImGui(window, !options.screenshot.empty(), &events);
  int code = 0;
  {
    GuiApp app(options, window, &events, &state);
    code = app.Run();
  }
  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  glfwDestroyWindow(window);
  glfwTerminate();
  return code;
}

}  // namespace fresco
