#include "gl.h"

namespace tumble::viewer {

bool Gl::load(Loader loader, std::string* missing) {
  missing->clear();
#define TUMBLE_GL_LOAD(type, name)                   \
  name = reinterpret_cast<type>(loader("gl" #name)); \
  if (name == nullptr) *missing += (missing->empty() ? "gl" : ", gl") + std::string(#name);
  TUMBLE_GL_FUNCTIONS(TUMBLE_GL_LOAD)
#undef TUMBLE_GL_LOAD
  return missing->empty();
}

}  // namespace tumble::viewer
