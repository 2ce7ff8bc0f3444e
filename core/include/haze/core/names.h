// One table of an enum's names, which parsing, printing and a setting's choices all read, so that
// each name is written once (`inline constexpr Named<E> kTable[] = {{E::a, "a"}, ...}`).
#pragma once

#include <haze/core/error.h>

#include <span>
#include <string>
#include <vector>

namespace haze {

template <class E>
struct Named {
  E value;
  const char* name;
};

// The names in the table's order, for SettingInfo::choice.
template <class E>
std::vector<std::string> names_of(std::span<const Named<E>> table) {
  std::vector<std::string> out;
  for (const Named<E>& n : table) out.emplace_back(n.name);
  return out;
}

// The value called `name`; a haze::Error naming `field`, with the names it takes, when none is.
template <class E>
E from_name(std::span<const Named<E>> table, const std::string& name, const std::string& field) {
  for (const Named<E>& n : table)
    if (name == n.name) return n.value;
  std::string expected;
  for (const Named<E>& n : table) expected += (expected.empty() ? "one of \"" : ", \"") + std::string(n.name) + "\"";
  throw Error(field, "\"" + name + "\"", expected);
}

// The value's name ("?" for a value the table lacks).
template <class E>
const char* name_of(std::span<const Named<E>> table, E value) {
  for (const Named<E>& n : table)
    if (n.value == value) return n.name;
  return "?";
}

}  // namespace haze
