#include <haze/core/error.h>

namespace haze {

namespace {

// A field or value of a message, cut where it would flood a terminal (a 50 MB key echoed whole).
std::string shortened(std::string s) {
  constexpr size_t kLimit = 240;
  if (s.size() > kLimit) s = s.substr(0, 200) + "... (" + std::to_string(s.size()) + " characters)";
  return s;
}

}  // namespace

Error::Error(std::string field, std::string value, std::string expected)
    : Error(shortened(std::move(field)), shortened(std::move(value)), std::move(expected), 0) {}

Error::Error(std::string field, std::string value, std::string expected, int)
    : std::runtime_error(field + ": got " + value + ", expected " + expected),
      field_(std::move(field)),
      value_(std::move(value)),
      expected_(std::move(expected)) {}

namespace internal {
void check_failed(const char* condition, const char* file, int line) {
  throw Error(std::string("internal check failed: ") + condition + " at " + file + ":" + std::to_string(line) +
              " (a bug in Haze; please report it)");
}
}  // namespace internal

}  // namespace haze
