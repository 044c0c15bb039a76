// Input events queued between frames, so that short key taps, fast drags and text typed right
// after a click are not lost or misplaced when frames are slow. Dear ImGui 1.86 reads the keyboard
// and the mouse as states sampled once per frame: a key pressed and released within one frame, or a
// drag pressed, moved and released within one, never shows up (ImGui 1.87's input queue does this
// trickling). The window's callbacks push events here; each frame takes events in order until one
// would change something that already changed this frame, and leaves the rest for the next frame.
// Pure logic: the state struct is copied into ImGuiIO by CopyToImGui.
#pragma once

#include <array>
#include <cfloat>
#include <cstddef>
#include <deque>
#include <vector>

struct ImGuiIO;

namespace fresco {

// Key codes are the window backend's (GLFW's: ImGui 1.86 indexes io.KeysDown by them).
inline constexpr int kKeyLeftShift = 340, kKeyLeftControl = 341, kKeyLeftAlt = 342,
                     kKeyLeftSuper = 343, kKeyRightShift = 344, kKeyRightControl = 345,
                     kKeyRightAlt = 346, kKeyRightSuper = 347;

struct InputEvent {
  enum class Kind { kMouseMove, kMouseButton, kWheel, kKey, kChar };
  Kind kind = Kind::kMouseMove;
  float x = 0, y = 0;  // kMouseMove: position, pixels; kWheel: offsets
  int code = 0;        // kMouseButton: button 0..4; kKey: key code (0..511); kChar: code point
  bool down = false;   // kMouseButton, kKey: pressed (true) or released
};

// What one frame sees.
struct InputState {
  float mouse_x = -FLT_MAX, mouse_y = -FLT_MAX;  // -FLT_MAX: no mouse over the window
  std::array<bool, 5> mouse_down{};
  float wheel_x = 0, wheel_y = 0;  // this frame's scrolling
  std::array<bool, 512> keys_down{};
  std::vector<unsigned int> chars;  // this frame's typed text (code points)
};

class InputQueue {
 public:
  void Push(const InputEvent& event) { events_.push_back(event); }
  // Advances `state` by one frame's events: in order, until a key or button would change a
  // second time, a button would change after the mouse moved, the mouse would move after a
  // button or key changed, or a key would change after a button changed (so a press, each
  // drag step and the release land in frames of their own, at the positions they happened,
  // and a ctrl-click's release still sees ctrl held), or a modifier (Ctrl, Shift, Alt, Super)
  // would change after another key went down (a chord whose Ctrl is let go right after its
  // key still has Ctrl held in the frame its key goes down). Typed text waits after a button
  // changed or the mouse moved (a click into a field moves the focus first: the text lands in the
  // field clicked, not the one before), and a key waits after typed text (as typed). The
  // wheel is this frame's sum.
  // Returns how many events this frame took; the rest stay queued.
  int NextFrame(InputState* state);
  size_t pending() const { return events_.size(); }

 private:
  std::deque<InputEvent> events_;
};

// Copies a frame's input into Dear ImGui (MousePos, MouseDown, MouseWheel, KeysDown, the
// modifiers from the keys above, and the typed text).
void CopyToImGui(const InputState& state, ImGuiIO* io);

}  // namespace fresco
