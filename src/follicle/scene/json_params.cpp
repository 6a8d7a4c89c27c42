#include "follicle/scene/json_params.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <functional>
#include <set>

#include "follicle/core/atomic_file.hpp"

namespace follicle::scene {

namespace {

struct DuplicateKey {
  std::string key;
};

std::string where(const JsonSource& src, const std::string& path) {
  const std::string p = path.empty() ? "(top level)" : path;
  return src.file.empty() ? p : src.file + ": " + p;
}

}  // namespace

Json parse_json_text(const std::string& text, const std::string& file_for_errors) {
  const std::string file = file_for_errors.empty() ? "<json>" : file_for_errors;
  // nlohmann keeps the last of two equal keys silently; a strict scene reader must not.
  std::vector<std::set<std::string>> keys;
  Json::parser_callback_t cb = [&keys](int, Json::parse_event_t ev, Json& parsed) {
    if (ev == Json::parse_event_t::object_start) {
      keys.emplace_back();
    } else if (ev == Json::parse_event_t::object_end) {
      if (!keys.empty()) keys.pop_back();
    } else if (ev == Json::parse_event_t::key) {
      const auto k = parsed.get<std::string>();
      if (!keys.empty() && !keys.back().insert(k).second) throw DuplicateKey{k};
    }
    return true;
  };
  try {
    return Json::parse(text, cb);
  } catch (const DuplicateKey& d) {
    fail_at(file, "invalid JSON: duplicate key \"{}\" in an object", d.key);
  } catch (const Json::parse_error& e) {
    // Line/column from the byte offset; the message without nlohmann's "[json.exception...]
    // parse error at line L, column C: " prefix.
    const std::size_t byte = std::min<std::size_t>(e.byte == 0 ? 0 : e.byte - 1, text.size());
    std::size_t line = 1, col = 1;
    for (std::size_t i = 0; i < byte; ++i) {
      if (text[i] == '\n') {
        ++line;
        col = 1;
      } else {
        ++col;
      }
    }
    std::string msg = e.what();
    if (auto c = msg.find("column "); c != std::string::npos) {
      if (auto colon = msg.find(": ", c); colon != std::string::npos) msg = msg.substr(colon + 2);
    } else if (auto b = msg.find("] "); b != std::string::npos) {
      msg = msg.substr(b + 2);
    }
    fail_at(fmt::format("{}:{}:{}", file, line, col), "invalid JSON: {}", msg);
  } catch (const Json::out_of_range& e) {
    // A number too large for a double ("1e999"): nlohmann gives no position, only the text of
    // the number, so the number is looked up in the text for its line and column.
    std::string msg = e.what();
    if (auto b = msg.find("] "); b != std::string::npos) msg = msg.substr(b + 2);
    std::string where = file;
    const auto q0 = msg.find('\''), q1 = msg.rfind('\'');
    if (q0 != std::string::npos && q1 > q0 + 1) {
      if (const auto at = text.find(msg.substr(q0 + 1, q1 - q0 - 1)); at != std::string::npos) {
        const std::size_t line = 1 + std::size_t(std::count(text.begin(), text.begin() + at, '\n'));
        const auto nl = text.rfind('\n', at);
        const std::size_t col = at - (nl == std::string::npos ? 0 : nl + 1) + 1;
        where = fmt::format("{}:{}:{}", file, line, col);
      }
    }
    fail_at(where, "invalid JSON: {} (larger than a double can hold)", msg);
  }
}

Json parse_json_file(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) fail_at(path.string(), "file not found");
  if (std::filesystem::is_directory(path)) fail_at(path.string(), "is a directory, not a file");
  return parse_json_text(read_file(path), path.string());
}

std::string describe_json(const Json& j) {
  auto shorten = [](std::string s) {
    if (s.size() > 40) s = s.substr(0, 37) + "...";
    return s;
  };
  switch (j.type()) {
    case Json::value_t::null: return "null";
    case Json::value_t::boolean: return j.get<bool>() ? "true" : "false";
    case Json::value_t::string: return "a string " + shorten(j.dump());
    case Json::value_t::number_integer:
    case Json::value_t::number_unsigned:
    case Json::value_t::number_float: return "a number " + j.dump();
    case Json::value_t::array: return fmt::format("an array of {} element(s)", j.size());
    case Json::value_t::object: return "an object";
    default: return "an unsupported JSON value";
  }
}

std::string join_path(const std::string& path, const std::string& key) {
  return path.empty() ? key : path + "." + key;
}

std::string index_path(const std::string& path, std::size_t i) {
  return fmt::format("{}[{}]", path, i);
}

void json_fail(const JsonSource& src, const std::string& path, const std::string& what) {
  throw Error(where(src, path), what);
}

std::string suggest(const std::string& key, const std::vector<std::string>& known) {
  // A truncated or extended name ("fov" for "fov_deg") is the likeliest mistake, even when the
  // plain edit distance prefers another key ("far"); then fall back to the edit distance.
  std::string best;
  for (const auto& k : known) {
    const bool prefix =
        (key.size() >= 2 && k.rfind(key, 0) == 0) || (k.size() >= 3 && key.rfind(k, 0) == 0);
    if (prefix && (best.empty() || edit_distance(key, k) < edit_distance(key, best))) best = k;
  }
  return best.empty() ? did_you_mean(key, known) : best;
}

void json_fail_unknown_key(const JsonSource& src, const std::string& path, const std::string& key,
                           const std::vector<std::string>& known) {
  const std::string hint = suggest(key, known);
  json_fail(src, join_path(path, key),
            "unknown key \"" + key + "\"" +
                (hint.empty() ? std::string() : " (did you mean \"" + hint + "\"?)") +
                "; accepted keys: " + (known.empty() ? "none" : detail::quoted_list(known)));
}

namespace detail {

std::string quoted_list(const std::vector<std::string>& names) {
  std::string out;
  for (const auto& n : names) {
    if (!out.empty()) out += ", ";
    out += '"';
    out += n;
    out += '"';
  }
  return out;
}

std::string format_bound(double v) {
  if (v == std::numeric_limits<double>::infinity()) return "inf";
  if (v == -std::numeric_limits<double>::infinity()) return "-inf";
  return fmt::format("{}", v);
}

void check_number_range(const JsonSource& src, const std::string& path, double v,
                        const ParamInfo& info) {
  if (!std::isfinite(v)) json_fail(src, path, fmt::format("value {} is not a finite number", v));
  if (v < info.min || v > info.max) {
    json_fail(src, path,
              fmt::format("value {} is out of range [{}, {}]{}{}", v, format_bound(info.min),
                          format_bound(info.max),
                          *info.unit ? std::string(" ") + info.unit : std::string(),
                          *info.doc ? fmt::format(" ({})", info.doc) : std::string()));
  }
}

std::string doc_range(const ParamInfo& info, bool numeric) {
  if (!numeric) return "";
  const bool lo = std::isfinite(info.min), hi = std::isfinite(info.max);
  if (!lo && !hi) return "";
  if (lo && hi) return fmt::format("[{}, {}]", info.min, info.max);
  if (lo) return fmt::format("≥ {}", info.min);
  return fmt::format("≤ {}", info.max);
}

std::string doc_default(const Json& j) {
  if (j.is_null()) return "(none)";
  if (j.is_string() && j.get<std::string>().empty()) return "\"\"";
  if (j.is_array() && j.empty()) return "`[]`";
  if (j.is_object() && j.empty()) return "`{}`";
  if (j.is_array() && !j.empty() && j[0].is_object()) return fmt::format("{} entries", j.size());
  Json r = j;
  // Round floats for the table (0.30000000000000004 -> 0.3).
  std::function<void(Json&)> round = [&](Json& x) {
    if (x.is_number_float()) x = std::stod(fmt::format("{:.6g}", x.get<double>()));
    if (x.is_array())
      for (auto& e : x) round(e);
  };
  round(r);
  std::string out = "`";
  out += r.dump();
  out += '`';
  return out;
}

}  // namespace detail

std::string doc_table(const std::vector<DocRow>& rows) {
  auto esc = [](std::string s) {
    std::string out;
    for (char c : s) {
      if (c == '|')
        out += "\\|";
      else
        out += c;
    }
    return out;
  };
  std::string out =
      "| key | type | unit | default | range | meaning |\n|---|---|---|---|---|---|\n";
  for (const auto& r : rows) {
    out += fmt::format("| `{}` | {} | {} | {} | {} | {} |\n", r.key, esc(r.type), esc(r.unit),
                       esc(r.default_value), esc(r.range), esc(r.doc));
  }
  return out;
}

}  // namespace follicle::scene
