// The YAML reading machinery of the configuration loader, shared by the whole configuration
// (config.cpp) and the traits options alone (traits_config.cpp), which is a library of its own so
// that `fieldrig traits` links neither cameras nor OpenCV. Internal to config/.
#pragma once

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <functional>
#include <limits>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>
#include <system_error>
#include <utility>
#include <vector>

#include "fieldrig/core/result.h"

namespace fieldrig::config::detail {

namespace fs = std::filesystem;

// The loader's one failure, already worded "FILE:LINE: key.path: what". Thrown inside config/src
// only and turned into a core::Error at the entry points (start-up code, never the live path).
struct LoadFailure {
  std::string message;
};

// Where the text came from: it names the text in messages and anchors its relative paths.
struct Source {
  std::string origin;
  fs::path base_dir;
};

inline std::string lineSuffix(const YAML::Mark& mark) {
  if (mark.is_null() || mark.line < 0)
    return {};
  return ":" + std::to_string(mark.line + 1);
}

inline std::string formatNumber(double value) {
  std::ostringstream out;
  out << value;
  return out.str();
}

// "a, b or c" (choices), or "a, b, c" with last_separator ", " (a sequence).
inline std::string joinNames(const std::vector<std::string>& names,
                             const std::string& last_separator = " or ") {
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0)
      joined += i + 1 == names.size() ? last_separator : ", ";
    joined += names[i];
  }
  return joined;
}

// Edit distance, for "did you mean" on unknown keys.
inline std::size_t editDistance(std::string_view a, std::string_view b) {
  std::vector<std::size_t> row(b.size() + 1);
  for (std::size_t j = 0; j <= b.size(); ++j)
    row[j] = j;
  for (std::size_t i = 1; i <= a.size(); ++i) {
    std::size_t diagonal = row[0];
    row[0] = i;
    for (std::size_t j = 1; j <= b.size(); ++j) {
      const std::size_t above = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, diagonal + (a[i - 1] == b[j - 1] ? 0 : 1)});
      diagonal = above;
    }
  }
  return row[b.size()];
}

// One value of the file: its node, its key path ("gps.serial.baud") and the place errors point
// at. Readers fail with a LoadFailure naming all three.
class Value {
 public:
  Value(const Source& source, YAML::Node node, std::string key_path, YAML::Mark mark)
      : source_(&source), node_(std::move(node)), key_path_(std::move(key_path)), mark_(mark) {}

  const Source& source() const { return *source_; }
  const YAML::Node& node() const { return node_; }
  const std::string& keyPath() const { return key_path_; }
  const YAML::Mark& mark() const { return mark_; }
  int line() const { return mark_.line + 1; }
  std::string childPath(std::string_view key) const {
    return key_path_.empty() ? std::string(key) : key_path_ + "." + std::string(key);
  }

  [[noreturn]] void fail(const std::string& what) const {
    std::string message = source_->origin + lineSuffix(mark_) + ": ";
    if (!key_path_.empty())
      message += key_path_ + ": ";
    throw LoadFailure{message + what};
  }

  // What the node is, for "expected …, got …".
  std::string describe() const {
    if (node_.IsNull())
      return "nothing";
    if (node_.IsSequence())
      return "a list";
    if (node_.IsMap())
      return "a map";
    if (isPlainScalar())
      return "'" + node_.Scalar() + "'";
    return "the string \"" + node_.Scalar() + "\"";
  }

  // Any scalar, quoted or not.
  const std::string& text() const {
    if (!node_.IsScalar())
      fail("expected a text value, got " + describe());
    return node_.Scalar();
  }

  double number() const {
    const std::string& t = plainScalar("a number");
    std::string_view digits = t;
    if (digits.starts_with('+'))
      digits.remove_prefix(1);
    double value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty())
      fail("expected a number, got " + describe());
    if (!std::isfinite(value))
      fail(t + " is not a finite number");
    return value;
  }

  std::int64_t integer() const {
    const std::string& t = plainScalar("an integer");
    std::string_view digits = t;
    if (digits.starts_with('+'))
      digits.remove_prefix(1);
    std::int64_t value = 0;
    const auto [end, ec] = std::from_chars(digits.data(), digits.data() + digits.size(), value);
    if (ec == std::errc::result_out_of_range)
      fail(t + " is out of range");
    if (ec != std::errc() || end != digits.data() + digits.size() || digits.empty())
      fail("expected an integer, got " + describe());
    return value;
  }

  bool boolean() const {
    std::string t = plainScalar("true or false");
    std::transform(t.begin(), t.end(), t.begin(),
                   [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
    if (t == "true" || t == "yes" || t == "on")
      return true;
    if (t == "false" || t == "no" || t == "off")
      return false;
    fail("expected true or false, got " + describe());
  }

  // A file or folder; a relative one is taken relative to the configuration file's folder.
  // Empty stays empty (nothing configured).
  fs::path path() const {
    const std::string& t = text();
    if (t.empty())
      return {};
    fs::path p(t);
    if (p.is_relative() && !source_->base_dir.empty())
      p = source_->base_dir / p;
    return p.lexically_normal();
  }

  // The elements of a list, each with its path "key[i]".
  std::vector<Value> list() const {
    if (!node_.IsSequence())
      fail("expected a list, got " + describe());
    std::vector<Value> items;
    for (std::size_t i = 0; i < node_.size(); ++i) {
      const YAML::Node item = node_[i];
      items.emplace_back(*source_, item, key_path_ + "[" + std::to_string(i) + "]",
                         item.Mark().is_null() ? mark_ : item.Mark());
    }
    return items;
  }

 private:
  bool isPlainScalar() const { return node_.IsScalar() && node_.Tag() == "?"; }

  // Numbers and booleans are plain scalars: a quoted "115200" is a string, and an error.
  const std::string& plainScalar(const std::string& expected) const {
    if (!isPlainScalar())
      fail("expected " + expected + ", got " + describe());
    return node_.Scalar();
  }

  const Source* source_;
  YAML::Node node_;
  std::string key_path_;
  YAML::Mark mark_;
};

// --- Range-checked readers ----------------------------------------------------------------------

// Every number of the file is finite (Value::number) and bounded above too: a value beyond `hi`
// is a typo or a unit mistake that would otherwise make the daemon wait, allocate or miss for
// ever. The defaults of `hi` are for the few values with no natural ceiling.
inline double readPositive(const Value& v, double hi = std::numeric_limits<double>::max()) {
  const double x = v.number();
  if (!(x > 0))
    v.fail(v.node().Scalar() + " must be positive");
  if (x > hi)
    v.fail(v.node().Scalar() + " is out of range (0, " + formatNumber(hi) + "]");
  return x;
}

inline double readNonNegative(const Value& v, double hi = std::numeric_limits<double>::max()) {
  const double x = v.number();
  if (x < 0)
    v.fail(v.node().Scalar() + " must not be negative");
  if (x > hi)
    v.fail(v.node().Scalar() + " is out of range [0, " + formatNumber(hi) + "]");
  return x;
}

// [lo, hi], or [lo, hi) when hi_open.
inline double readNumberIn(const Value& v, double lo, double hi, bool hi_open = false) {
  const double x = v.number();
  if (x < lo || x > hi || (hi_open && x == hi)) {
    v.fail(v.node().Scalar() + " is out of range [" + formatNumber(lo) + ", " + formatNumber(hi) +
           (hi_open ? ")" : "]"));
  }
  return x;
}

inline std::int64_t readIntegerIn(const Value& v, std::int64_t lo, std::int64_t hi) {
  const std::int64_t x = v.integer();
  if (x >= lo && x <= hi)
    return x;
  const bool no_upper_limit =
      hi == std::numeric_limits<std::int64_t>::max() || hi == std::numeric_limits<int>::max();
  const bool no_lower_limit =
      lo == std::numeric_limits<std::int64_t>::min() || lo == std::numeric_limits<int>::min();
  if (no_upper_limit && x > hi)
    v.fail(v.node().Scalar() + " is too large");
  if (no_upper_limit && !no_lower_limit) {
    if (lo == 0)
      v.fail(v.node().Scalar() + " must not be negative");
    if (lo == 1)
      v.fail(v.node().Scalar() + " must be positive");
    v.fail(v.node().Scalar() + " must be at least " + std::to_string(lo));
  }
  v.fail(v.node().Scalar() + " is out of range (" + std::to_string(lo) + " … " +
         std::to_string(hi) + ")");
}

inline int readInt(const Value& v, int lo = std::numeric_limits<int>::min(),
                   int hi = std::numeric_limits<int>::max()) {
  return static_cast<int>(readIntegerIn(v, lo, hi));
}

inline std::string readNonEmptyText(const Value& v) {
  const std::string& t = v.text();
  if (t.empty())
    v.fail("must not be empty");
  return t;
}

template <typename E>
using Names = std::vector<std::pair<std::string_view, E>>;

template <typename E>
E readChoice(const Value& v, const Names<E>& names) {
  const std::string& t = v.text();
  std::vector<std::string> known;
  for (const auto& [name, value] : names) {
    if (name == t)
      return value;
    known.emplace_back(name);
  }
  v.fail("'" + t + "' is not one of " + joinNames(known));
}

// --- Maps of keys
// ---------------------------------------------------------------------------------

using Handler = std::function<void(const Value&)>;
using Handlers = std::vector<std::pair<std::string_view, Handler>>;
// The keys a map held, for checks between keys.
using Entries = std::map<std::string, Value, std::less<>>;

// Hands each key of the map (in file order) to its handler; an unknown or repeated key is an
// error. Nothing (a section whose keys are all commented out) reads as an empty map.
inline Entries readMap(const Value& section, const Handlers& handlers) {
  Entries entries;
  const YAML::Node& node = section.node();
  if (node.IsNull())
    return entries;
  if (!node.IsMap())
    section.fail("expected a map of keys, got " + section.describe());
  for (auto it = node.begin(); it != node.end(); ++it) {
    const YAML::Node key_node = it->first;
    const YAML::Node value_node = it->second;
    const Value key(section.source(), key_node, section.keyPath(), key_node.Mark());
    if (!key_node.IsScalar())
      key.fail("expected a key name, got " + key.describe());
    const std::string& name = key_node.Scalar();
    const Value at_key(section.source(), key_node, section.childPath(name), key_node.Mark());
    const auto handler = std::find_if(handlers.begin(), handlers.end(),
                                      [&](const auto& entry) { return entry.first == name; });
    if (handler == handlers.end()) {
      std::vector<std::string> known;
      std::string_view nearest;
      std::size_t nearest_distance = 3;
      for (const auto& [known_name, _] : handlers) {
        known.emplace_back(known_name);
        const std::size_t distance = editDistance(name, known_name);
        if (distance < nearest_distance) {
          nearest = known_name;
          nearest_distance = distance;
        }
      }
      if (!nearest.empty())
        at_key.fail("unknown key (did you mean '" + std::string(nearest) + "'?)");
      at_key.fail("unknown key (known here: " + joinNames(known) + ")");
    }
    if (const auto first = entries.find(name); first != entries.end())
      at_key.fail("given twice (first on line " + std::to_string(first->second.line()) + ")");
    // A key without a value has no useful place of its own: point at the key.
    const YAML::Mark mark =
        value_node.IsNull() || value_node.Mark().is_null() ? key_node.Mark() : value_node.Mark();
    const Value value(section.source(), value_node, section.childPath(name), mark);
    entries.emplace(name, value);
    handler->second(value);
  }
  return entries;
}

// Handlers that store into a field.
inline Handler positive(double& field, double hi = std::numeric_limits<double>::max()) {
  return [&field, hi](const Value& v) { field = readPositive(v, hi); };
}
inline Handler nonNegative(double& field, double hi = std::numeric_limits<double>::max()) {
  return [&field, hi](const Value& v) { field = readNonNegative(v, hi); };
}
inline Handler numberIn(double& field, double lo, double hi, bool hi_open = false) {
  return [&field, lo, hi, hi_open](const Value& v) { field = readNumberIn(v, lo, hi, hi_open); };
}
inline Handler integer(int& field, int lo = std::numeric_limits<int>::min(),
                       int hi = std::numeric_limits<int>::max()) {
  return [&field, lo, hi](const Value& v) { field = readInt(v, lo, hi); };
}
inline Handler flag(bool& field) {
  return [&field](const Value& v) { field = v.boolean(); };
}
inline Handler location(fs::path& field) {
  return [&field](const Value& v) { field = v.path(); };
}
template <typename E>
Handler choice(E& field, Names<E> names) {
  return [&field, names = std::move(names)](const Value& v) { field = readChoice(v, names); };
}

// The entry of `key` if the map held it, else the section (for the place of an error).
inline const Value& entryOr(const Entries& entries, std::string_view key, const Value& section) {
  const auto it = entries.find(key);
  return it == entries.end() ? section : it->second;
}

// YAML allows no C0 control character but tab and line breaks; yaml-cpp 0.7 loops forever on some
// (a NUL inside a flow map: the config fuzzer found it), so the text is checked before it.
inline void refuseControlCharacters(const Source& source, const std::string& text) {
  const auto bad = std::find_if(text.begin(), text.end(), [](char c) {
    const auto byte = static_cast<unsigned char>(c);
    return (byte < 0x20 && c != '\t' && c != '\n' && c != '\r') || byte == 0x7f;
  });
  if (bad == text.end())
    return;
  const auto line = 1 + std::count(text.begin(), bad, '\n');
  char code[8];
  std::snprintf(code, sizeof code, "0x%02x",
                static_cast<unsigned>(static_cast<unsigned char>(*bad)));
  throw LoadFailure{source.origin + ":" + std::to_string(line) + ": a control character (" + code +
                    ") in the text; YAML allows none but tab and line breaks"};
}

// Where a document of a text starts, and where its first value does (the line errors name).
class DocumentStarts : public YAML::EventHandler {
 public:
  YAML::Mark start;
  std::optional<YAML::Mark> value;

  void OnDocumentStart(const YAML::Mark& mark) override { start = mark; }
  void OnDocumentEnd() override {}
  void OnNull(const YAML::Mark& mark, YAML::anchor_t) override { at(mark); }
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { at(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    at(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    at(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    at(mark);
  }
  void OnMapEnd() override {}

 private:
  void at(const YAML::Mark& mark) {
    if (!value)
      value = mark;
  }
};

// The one document of the text (nothing at all for an empty or comments-only text).
//
// Not YAML::LoadAll: yaml-cpp 0.7's parser yields empty documents at the same place forever after
// a ',' outside a flow collection ("," alone, or "- a\n,"), and LoadAll never returns (the traits
// options fuzzer found it). The documents are counted first, at most three: one that starts where
// the one before it did made no progress and is a syntax error at its line.
inline YAML::Node parseDocument(const Source& source, const std::string& text) {
  refuseControlCharacters(source, text);
  std::vector<DocumentStarts> documents;
  YAML::Node first;
  try {
    std::istringstream in(text);
    YAML::Parser parser(in);
    while (documents.size() < 3) {
      DocumentStarts document;
      if (!parser.HandleNextDocument(document))
        break;
      if (!documents.empty() && document.start.pos == documents.back().start.pos) {
        throw LoadFailure{source.origin + lineSuffix(document.start) +
                          ": YAML syntax error: text outside any value (a stray ',')"};
      }
      documents.push_back(document);
    }
    if (!documents.empty())
      first = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw LoadFailure{source.origin + lineSuffix(e.mark) + ": YAML syntax error: " + e.msg};
  }
  if (documents.size() > 1) {
    Value(source, YAML::Node(), "", documents[1].value.value_or(documents[1].start))
        .fail("a second YAML document ('---'); one file holds one configuration");
  }
  return first;
}

inline Value rootValue(const Source& source, const YAML::Node& document) {
  YAML::Mark mark = document.Mark();
  if (mark.is_null())
    mark = YAML::Mark();  // line 0: the file's first line
  const Value root(source, document, "", mark);
  if (!document.IsNull() && !document.IsMap())
    root.fail("expected a map of sections at the top of the file, got " + root.describe());
  return root;
}

// Runs a reader, turning its failure into the Result's error.
template <typename T, typename F>
core::Result<T> guarded(const std::string& origin, F&& read) {
  try {
    return read();
  } catch (const LoadFailure& failure) {
    return core::Error{failure.message};
  } catch (const YAML::Exception& e) {
    return core::Error{origin + lineSuffix(e.mark) + ": " + e.msg};
  }
}

inline core::Result<std::string> readFile(const fs::path& file) {
  std::error_code ec;
  if (fs::is_directory(file, ec))
    return core::Error{file.string() + ": cannot open: it is a folder"};
  std::ifstream in(file, std::ios::binary);
  if (!in) {
    const int error = errno;
    return core::Error{file.string() + ": cannot open: " +
                       std::error_code(error, std::generic_category()).message()};
  }
  std::ostringstream text;
  text << in.rdbuf();
  if (in.bad())
    return core::Error{file.string() + ": cannot read: " +
                       std::error_code(errno, std::generic_category()).message()};
  return text.str();
}

// The folder relative paths of `file` are taken against.
inline fs::path folderOf(const fs::path& file) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(file, ec);
  return (ec ? file : absolute).parent_path().lexically_normal();
}

}  // namespace fieldrig::config::detail
