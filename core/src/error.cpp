#include <haze/core/error.h>

namespace haze {

Error::Error(std::string field, std::string value, std::string expected)
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
