#include "sonarbench/io/yaml_reader.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "sonarbench/base/atomic_file.hpp"
#include "sonarbench/base/error.hpp"
#include "sonarbench/io/files.hpp"
#include "sonarbench/io/text.hpp"

namespace sonarbench {
namespace {

std::string Describe(const YAML::Node& node) {
  if (!node.IsDefined() || node.IsNull()) return "nothing";
  if (node.IsScalar()) return "'" + node.Scalar() + "'";
  if (node.IsSequence()) return "a list";
  return "a mapping";
}

// yaml-cpp's as<double>() accepts "1e3" and also ".inf"/".nan"; we reject non-finite numbers.
std::optional<double> ToDouble(const YAML::Node& node) {
  if (!node.IsScalar()) return std::nullopt;
  double value = 0.0;
  if (!YAML::convert<double>::decode(node, value) || !std::isfinite(value)) return std::nullopt;
  return value;
}

std::optional<int> ToInt(const YAML::Node& node) {
  if (!node.IsScalar()) return std::nullopt;
  int value = 0;
  if (!YAML::convert<int>::decode(node, value)) return std::nullopt;
  return value;
}

template <typename T>
struct Decoder;

template <>
struct Decoder<double> {
  static constexpr const char* kWhat = "a finite number";
  static std::optional<double> Decode(const YAML::Node& n) { return ToDouble(n); }
};
template <>
struct Decoder<int> {
  static constexpr const char* kWhat = "an integer";
  static std::optional<int> Decode(const YAML::Node& n) { return ToInt(n); }
};
template <>
struct Decoder<std::uint64_t> {
  static constexpr const char* kWhat = "a non-negative integer";
  static std::optional<std::uint64_t> Decode(const YAML::Node& n) {
    std::uint64_t value = 0;
    if (!n.IsScalar() || n.Scalar().starts_with("-") ||
        !YAML::convert<std::uint64_t>::decode(n, value)) {
      return std::nullopt;
    }
    return value;
  }
};
template <>
struct Decoder<bool> {
  static constexpr const char* kWhat = "true or false";
  static std::optional<bool> Decode(const YAML::Node& n) {
    bool value = false;
    if (!n.IsScalar() || !YAML::convert<bool>::decode(n, value)) return std::nullopt;
    return value;
  }
};
template <>
struct Decoder<std::string> {
  static constexpr const char* kWhat = "a string";
  static std::optional<std::string> Decode(const YAML::Node& n) {
    if (!n.IsScalar()) return std::nullopt;
    return n.Scalar();
  }
};
template <>
struct Decoder<std::array<double, 3>> {
  static constexpr const char* kWhat = "a list of 3 finite numbers";
  static std::optional<std::array<double, 3>> Decode(const YAML::Node& n) {
    if (!n.IsSequence() || n.size() != 3) return std::nullopt;
    std::array<double, 3> out{};
    for (std::size_t i = 0; i < 3; ++i) {
      const auto v = ToDouble(n[i]);
      if (!v) return std::nullopt;
      out[i] = *v;
    }
    return out;
  }
};
template <>
struct Decoder<std::vector<double>> {
  static constexpr const char* kWhat = "a list of finite numbers";
  static std::optional<std::vector<double>> Decode(const YAML::Node& n) {
    if (!n.IsSequence()) return std::nullopt;
    std::vector<double> out;
    for (const auto& item : n) {
      const auto v = ToDouble(item);
      if (!v) return std::nullopt;
      out.push_back(*v);
    }
    return out;
  }
};

}  // namespace

YamlReader::YamlReader(YAML::Node node, std::shared_ptr<State> state, std::string path)
    : node_(std::move(node)), state_(std::move(state)), path_(std::move(path)) {
  if (!node_.IsMap()) {
    Record(Where(node_) + ": " + (path_.empty() ? std::string("document") : "key '" + path_ + "'") +
           ": expected a mapping, got " + Describe(node_));
    node_ = YAML::Node(YAML::NodeType::Map);
    not_a_mapping_ = true;
    return;
  }
  // yaml-cpp keeps duplicate keys and silently answers lookups with the first: report them, in
  // one message (a lost "- " merges two list items into one mapping of many duplicates).
  std::set<std::string> seen;
  std::optional<YAML::Node> first;
  std::string others;
  for (const auto& item : node_) {
    const std::string key = item.first.Scalar();
    if (seen.insert(key).second) continue;
    if (!first) {
      first.emplace(item.first);
    } else {
      others += (others.empty() ? "; so are '" : "', '") + key;
    }
  }
  if (first) {
    Record(Where(*first) + ": key '" + KeyPath(first->Scalar()) +
           "': duplicate key (each key may appear once" + (others.empty() ? "" : others + "'") +
           ")");
  }
}

YamlReader YamlReader::FromFile(const std::string& path) {
  // A directory, FIFO or device is refused by its type, a file past the budget by its size.
  return FromString(ReadFileBytes(path, kMaxYamlBytes), path);
}

YamlReader YamlReader::FromString(const std::string& text, const std::string& source_name) {
  if (!io::IsUtf8(text)) {
    // The first line that is not: names and paths go into UTF-8 JSON reports.
    std::size_t line = 1;
    for (std::size_t start = 0; start <= text.size(); ++line) {
      const std::size_t end = std::min(text.find('\n', start), text.size());
      const std::string_view part(text.data() + start, end - start);
      if (!io::IsUtf8(part)) {
        throw InputError(source_name + ":" + std::to_string(line) + ": " + io::Quoted(part) +
                         " is not UTF-8 text (expected a YAML file in UTF-8)");
      }
      start = end + 1;
    }
  }
  YAML::Node root;
  try {
    root = YAML::Load(text);
  } catch (const YAML::Exception& e) {
    throw InputError(source_name + ":" + std::to_string(e.mark.line + 1) + ":" +
                     std::to_string(e.mark.column + 1) + ": invalid YAML: " + e.msg);
  }
  auto state = std::make_shared<State>();
  state->file = source_name;
  return YamlReader(root, state, "");
}

std::string YamlReader::Where(const YAML::Node& node) const {
  const YAML::Mark mark = node.Mark();
  if (mark.is_null()) return state_->file;
  return state_->file + ":" + std::to_string(mark.line + 1) + ":" + std::to_string(mark.column + 1);
}

std::string YamlReader::KeyPath(const std::string& key) const {
  if (path_.empty()) return key;
  if (key.empty()) return path_;
  return path_ + "." + key;
}

YAML::Node YamlReader::Lookup(const std::string& key) {
  used_.insert(key);
  for (const auto& item : node_) {
    if (item.first.Scalar() == key) return item.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

bool YamlReader::Has(const std::string& key) const {
  for (const auto& item : node_) {
    if (item.first.Scalar() == key) return true;
  }
  return false;
}

std::vector<std::string> YamlReader::Keys() const {
  std::vector<std::string> keys;
  if (!node_.IsMap()) return keys;
  for (const auto& item : node_) keys.push_back(item.first.Scalar());
  return keys;
}

void YamlReader::Fail(const std::string& key, const std::string& expected) {
  // reset(), not `=`: assigning to a Node that shares node_ would overwrite node_ itself (yaml-cpp
  // assigns through to the referenced node), mid-iteration.
  YAML::Node at = node_;
  for (const auto& item : node_) {
    if (item.first.Scalar() == key) at.reset(item.second);
  }
  Record(Where(at) + ": key '" + KeyPath(key) + "': " + expected, Kind::kCheck);
}

template <typename T>
void YamlReader::Read(const std::string& key, const YAML::Node& value, T& out,
                      const Check<T>& check) {
  const auto decoded = Decoder<T>::Decode(value);
  if (!decoded) {
    Record(Where(value) + ": key '" + KeyPath(key) + "': expected " + Decoder<T>::kWhat + ", got " +
           Describe(value));
    return;
  }
  if (check) {
    if (const auto expected = check(*decoded)) {
      Record(Where(value) + ": key '" + KeyPath(key) + "': expected " + *expected + ", got " +
             Describe(value));
      return;
    }
  }
  out = *decoded;
}

template <typename T>
void YamlReader::Required(const std::string& key, T& out, Check<T> check) {
  const YAML::Node value = Lookup(key);
  if (!value.IsDefined()) {
    Record(Where(node_) + ": key '" + KeyPath(key) + "': missing (expected " + Decoder<T>::kWhat +
           ")");
    return;
  }
  Read(key, value, out, check);
}

template <typename T>
void YamlReader::Optional(const std::string& key, T& out, Check<T> check) {
  const YAML::Node value = Lookup(key);
  if (!value.IsDefined()) return;
  Read(key, value, out, check);
}

YamlReader YamlReader::Child(const std::string& key) {
  const YAML::Node value = Lookup(key);
  if (!value.IsDefined()) {
    Record(Where(node_) + ": key '" + KeyPath(key) + "': missing (expected a mapping)");
    YamlReader missing(YAML::Node(YAML::NodeType::Map), state_, KeyPath(key));
    missing.not_a_mapping_ = true;  // none of its keys is missing too
    return missing;
  }
  return YamlReader(value, state_, KeyPath(key));
}

std::optional<YamlReader> YamlReader::OptionalChild(const std::string& key) {
  const YAML::Node value = Lookup(key);
  if (!value.IsDefined()) return std::nullopt;
  return YamlReader(value, state_, KeyPath(key));
}

std::vector<YamlReader> YamlReader::Sequence(const std::string& key) {
  const YAML::Node value = Lookup(key);
  std::vector<YamlReader> out;
  if (!value.IsDefined() || !value.IsSequence() || value.size() == 0) {
    Record(Where(value.IsDefined() ? value : node_) + ": key '" + KeyPath(key) +
           "': expected a non-empty list of mappings, got " + Describe(value));
    return out;
  }
  for (std::size_t i = 0; i < value.size(); ++i) {
    out.push_back(YamlReader(value[i], state_, KeyPath(key) + "[" + std::to_string(i) + "]"));
  }
  return out;
}

void YamlReader::RejectUnknownKeys() {
  for (const auto& item : node_) {
    const std::string key = item.first.Scalar();
    if (!used_.contains(key)) {
      std::string known;
      for (const auto& k : used_) known += (known.empty() ? "" : ", ") + k;
      Record(Where(item.first) + ": key '" + KeyPath(key) + "': unknown key (known here: " + known +
             ")");
    }
  }
}

void YamlReader::Record(std::string message, Kind kind) {
  // A value that is not a mapping was reported as such; its keys and checks would only report
  // that again in other words. A check across values may rest on a refused one's default (a
  // glint's spread, a material's name): it waits until every value reads.
  if (not_a_mapping_ || (kind == Kind::kCheck && state_->value_refused)) return;
  if (kind == Kind::kRead) state_->value_refused = true;
  state_->errors.push_back(std::move(message));
}

void YamlReader::Ignore(const std::string& key) { used_.insert(key); }

void YamlReader::ThrowIfErrors() const {
  if (state_->errors.empty()) return;
  std::string message;
  for (const auto& e : state_->errors) message += (message.empty() ? "" : "\n") + e;
  throw InputError(message);
}

std::string YamlReader::WhereOf(const std::string& key) const {
  for (const auto& item : node_) {
    if (item.first.Scalar() == key) return Where(item.second);
  }
  return state_->file;
}

std::string YamlReader::Directory() const {
  return std::filesystem::path(state_->file).parent_path().string();
}

YamlReader::Check<double> Positive() {
  return [](const double& v) -> std::optional<std::string> {
    if (v > 0.0) return std::nullopt;
    return "a number > 0";
  };
}

YamlReader::Check<double> NonNegative() {
  return [](const double& v) -> std::optional<std::string> {
    if (v >= 0.0) return std::nullopt;
    return "a number >= 0";
  };
}

YamlReader::Check<double> InRange(double lo, double hi) {
  return [lo, hi](const double& v) -> std::optional<std::string> {
    if (v >= lo && v <= hi) return std::nullopt;
    std::ostringstream s;
    s << "a number in [" << lo << ", " << hi << "]";
    return s.str();
  };
}

YamlReader::Check<int> PositiveInt() {
  return [](const int& v) -> std::optional<std::string> {
    if (v > 0) return std::nullopt;
    return "an integer > 0";
  };
}

YamlReader::Check<int> IntInRange(int lo, int hi) {
  return [lo, hi](const int& v) -> std::optional<std::string> {
    if (v >= lo && v <= hi) return std::nullopt;
    return "an integer in [" + std::to_string(lo) + ", " + std::to_string(hi) + "]";
  };
}

YamlReader::Check<std::string> OneOf(std::vector<std::string> choices) {
  return [choices = std::move(choices)](const std::string& v) -> std::optional<std::string> {
    std::string all;
    for (const auto& c : choices) {
      if (c == v) return std::nullopt;
      all += (all.empty() ? "" : ", ") + c;
    }
    return "one of: " + all;
  };
}

YamlReader::Check<std::string> NonEmpty() {
  return [](const std::string& v) -> std::optional<std::string> {
    if (!v.empty() && v.size() <= 4096) return std::nullopt;
    return "a non-empty string of at most 4096 bytes";
  };
}

YamlReader::Check<std::string> Name() {
  return [](const std::string& v) -> std::optional<std::string> {
    if (!v.empty() && v.size() <= kMaxNameBytes) return std::nullopt;
    return "a name of 1 to " + std::to_string(kMaxNameBytes) + " bytes";
  };
}

#define SONARBENCH_INSTANTIATE(T)                                          \
  template void YamlReader::Required<T>(const std::string&, T&, Check<T>); \
  template void YamlReader::Optional<T>(const std::string&, T&, Check<T>);
SONARBENCH_INSTANTIATE(double)
SONARBENCH_INSTANTIATE(int)
SONARBENCH_INSTANTIATE(std::uint64_t)
SONARBENCH_INSTANTIATE(bool)
SONARBENCH_INSTANTIATE(std::string)
using Array3 = std::array<double, 3>;
SONARBENCH_INSTANTIATE(Array3)
SONARBENCH_INSTANTIATE(std::vector<double>)
#undef SONARBENCH_INSTANTIATE

}  // namespace sonarbench
