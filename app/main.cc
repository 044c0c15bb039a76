// fresco: paints live video onto 3D models. See `fresco --help`.
#include <string>
#include <vector>

#include "app/commands.h"

int main(int argc, char** argv) {
  return fresco::Dispatch(std::vector<std::string>(argv + 1, argv + argc));
}
