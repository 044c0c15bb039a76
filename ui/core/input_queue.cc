#include "ui/core/input_queue.h"

#include <imgui.h>

namespace fresco {

namespace {

bool IsModifier(int code) { return code >= kKeyLeftShift && code <= kKeyRightSuper; }

}  // namespace

int InputQueue::NextFrame(InputState* state) {
  state->wheel_x = state->wheel_y = 0;
  state->chars.clear();
  std::array<bool, 5> button_changed{};
  std::array<bool, 512> key_changed{};
  bool any_button_changed = false, any_key_changed = false, moved = false, typed = false;
  bool other_key_pressed = false;  // a key that is not a modifier went down
  int taken = 0;
  while (!events_.empty()) {
    const InputEvent& e = events_.front();
    bool take = true;
    switch (e.kind) {
      case InputEvent::Kind::kMouseMove:
        take = !any_button_changed && !any_key_changed;
        if (take) state->mouse_x = e.x, state->mouse_y = e.y, moved = true;
        break;
      case InputEvent::Kind::kMouseButton:
        if (e.code < 0 || e.code >= static_cast<int>(state->mouse_down.size())) break;
        take = !button_changed[e.code] && !moved;
        if (take && state->mouse_down[e.code] != e.down) {
          state->mouse_down[e.code] = e.down;
          button_changed[e.code] = any_button_changed = true;
        }
        break;
      case InputEvent::Kind::kWheel:
        state->wheel_x += e.x;
        state->wheel_y += e.y;
        break;
      case InputEvent::Kind::kKey:
        if (e.code < 0 || e.code >= static_cast<int>(state->keys_down.size())) break;
        take = !key_changed[e.code] && !any_button_changed && !typed &&
               !(IsModifier(e.code) && other_key_pressed);
        if (take && state->keys_down[e.code] != e.down) {
          state->keys_down[e.code] = e.down;
          key_changed[e.code] = any_key_changed = true;
          other_key_pressed |= e.down && !IsModifier(e.code);
        }
        break;
      case InputEvent::Kind::kChar:
        take = !any_button_changed && !moved;
        if (take) state->chars.push_back(static_cast<unsigned int>(e.code)), typed = true;
        break;
    }
    if (!take) break;
    events_.pop_front();
    ++taken;
  }
  return taken;
}

void CopyToImGui(const InputState& state, ImGuiIO* io) {
  io->MousePos = ImVec2(state.mouse_x, state.mouse_y);
  for (size_t b = 0; b < state.mouse_down.size(); ++b) io->MouseDown[b] = state.mouse_down[b];
  io->MouseWheel += state.wheel_y;
  io->MouseWheelH += state.wheel_x;
  constexpr size_t kKeys = sizeof(io->KeysDown) / sizeof(io->KeysDown[0]);
  for (size_t k = 0; k < state.keys_down.size() && k < kKeys; ++k)
    io->KeysDown[k] = state.keys_down[k];
  const auto& keys = state.keys_down;
  io->KeyCtrl = keys[kKeyLeftControl] || keys[kKeyRightControl];
  io->KeyShift = keys[kKeyLeftShift] || keys[kKeyRightShift];
  io->KeyAlt = keys[kKeyLeftAlt] || keys[kKeyRightAlt];
  io->KeySuper = keys[kKeyLeftSuper] || keys[kKeyRightSuper];
  for (unsigned int c : state.chars) io->AddInputCharacter(c);
}

}  // namespace fresco
