#pragma once
// follicle::Error: the one exception type. It carries an optional location (file, line or JSON
// path) so a user sees where bad input came from, and what was expected.
#include <fmt/format.h>

#include <stdexcept>
#include <string>

namespace follicle {

class Error : public std::runtime_error {
 public:
  explicit Error(const std::string& what) : std::runtime_error(what) {}
  Error(const std::string& where, const std::string& what)
      : std::runtime_error(where.empty() ? what : where + ": " + what), m_where(where) {}
  const std::string& where() const { return m_where; }

 private:
  std::string m_where;
};

template <class... Args>
[[noreturn]] void fail(fmt::format_string<Args...> f, Args&&... args) {
  throw Error(fmt::format(f, std::forward<Args>(args)...));
}

template <class... Args>
[[noreturn]] void fail_at(const std::string& where, fmt::format_string<Args...> f, Args&&... args) {
  throw Error(where, fmt::format(f, std::forward<Args>(args)...));
}

}  // namespace follicle
