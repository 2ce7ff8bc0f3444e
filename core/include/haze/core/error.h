// haze::Error: the one exception type the library throws for bad input, and the CHECK macros
// for internal invariants. Library code never terminates the process and never prints.
#pragma once

#include <sstream>
#include <stdexcept>
#include <string>

#pragma GCC visibility push(default)  // the public API: exported from shared builds

namespace haze {

// An error a caller can act on: it names the field (a JSON path such as "medium.albedo[1]" or an
// API parameter), the offending value and what was expected. A field or value longer than 240
// characters is cut to its first 200 and its length.
class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& message) : std::runtime_error(message) {}
  Error(std::string field, std::string value, std::string expected);

  const std::string& field() const { return field_; }
  const std::string& value() const { return value_; }
  const std::string& expected() const { return expected_; }

 private:
  Error(std::string field, std::string value, std::string expected, int);  // already shortened
  std::string field_, value_, expected_;
};

// Thrown when a progress callback asks to stop long work.
class Cancelled : public Error {
 public:
  Cancelled() : Error("cancelled by the progress callback") {}
};

// Formats a value for an error message ("nan", "-0.5", "[1, 2, 3]").
template <typename T>
std::string to_text(const T& value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

namespace internal {
[[noreturn]] void check_failed(const char* condition, const char* file, int line);
}  // namespace internal

}  // namespace haze

// Internal invariants: a failure is a bug in Haze, reported as haze::Error (never abort()).
#define HAZE_CHECK(condition) \
  do {                        \
    if (!(condition)) ::haze::internal::check_failed(#condition, __FILE__, __LINE__); \
  } while (false)

#ifdef NDEBUG
#define HAZE_DCHECK(condition) \
  do {                         \
  } while (false)
#else
#define HAZE_DCHECK(condition) HAZE_CHECK(condition)
#endif

#pragma GCC visibility pop
