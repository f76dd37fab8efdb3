#pragma once

#include <yaml-cpp/yaml.h>

#include <array>
#include <functional>
#include <memory>
#include <optional>
#include <set>
#include <string>
#include <vector>

namespace sonarbench {

/// Reads one YAML mapping into a config struct, strictly: unknown keys, duplicate keys, missing
/// required keys, wrong types and out-of-range values are all collected, each as
/// "file:line:column: key 'a.b.c': expected ..., got ...", and thrown together as one
/// InputError by ThrowIfErrors() on the root reader. A value that should be a mapping and is not
/// is reported once: nothing read from it after that adds an error. Checks recorded with Fail()
/// are reported only while every value read so far was taken: one across keys would otherwise
/// report a refused value's default. Keys absent from an optional read keep the
/// struct's in-class default, so the struct stays the one source of truth for defaults.
class YamlReader {
 public:
  /// A check on a value: returns a description of what was expected if the value is bad.
  template <typename T>
  using Check = std::function<std::optional<std::string>(const T&)>;

  /// Parses `path`; a missing file or a YAML syntax error throws InputError at once.
  [[nodiscard]] static YamlReader FromFile(const std::string& path);
  /// Parses YAML text; `source_name` stands for the file in messages.
  [[nodiscard]] static YamlReader FromString(const std::string& text,
                                             const std::string& source_name);

  /// Reads a required key into `out`.
  template <typename T>
  void Required(const std::string& key, T& out, Check<T> check = {});
  /// Reads an optional key into `out`; when absent, `out` keeps its value.
  template <typename T>
  void Optional(const std::string& key, T& out, Check<T> check = {});

  /// A required or optional nested mapping; nullopt when an optional one is absent.
  [[nodiscard]] YamlReader Child(const std::string& key);
  [[nodiscard]] std::optional<YamlReader> OptionalChild(const std::string& key);
  /// A required sequence of mappings.
  [[nodiscard]] std::vector<YamlReader> Sequence(const std::string& key);

  [[nodiscard]] bool Has(const std::string& key) const;
  /// The keys of this mapping, in file order (for mappings keyed by name, such as criteria).
  [[nodiscard]] std::vector<std::string> Keys() const;
  /// Records an error at `key` (or at this node when `key` is empty): a check of values read,
  /// dropped when a value was refused before it.
  void Fail(const std::string& key, const std::string& expected);

  /// Takes `key` as known without reading it: for keys whose meaning depends on a value that was
  /// refused (a mesh's size under a `type` that is not one), so that they are not also reported.
  void Ignore(const std::string& key);

  /// Reports every key of this mapping that no Required/Optional/Child call asked for. Call it
  /// once per reader after reading all of its keys.
  void RejectUnknownKeys();
  /// Throws InputError listing every error collected so far by this reader and its children.
  void ThrowIfErrors() const;

  [[nodiscard]] const std::string& file() const { return state_->file; }
  /// The directory of the file, for resolving relative paths in it.
  [[nodiscard]] std::string Directory() const;
  /// "FILE:LINE:COLUMN" of `key`'s value in this mapping (the file alone when it has none).
  [[nodiscard]] std::string WhereOf(const std::string& key) const;

 private:
  struct State {
    std::string file;
    std::vector<std::string> errors;
    bool value_refused = false;  // a value was not taken (wrong type, range, key, shape)
  };
  enum class Kind { kRead, kCheck };  // an error reading a value, or a check on values read
  YamlReader(YAML::Node node, std::shared_ptr<State> state, std::string path);

  /// Adds an error, unless this reader's value was not a mapping (reported already) or it is a
  /// check and a value was refused.
  void Record(std::string message, Kind kind = Kind::kRead);
  [[nodiscard]] std::string Where(const YAML::Node& node) const;
  [[nodiscard]] std::string KeyPath(const std::string& key) const;
  [[nodiscard]] YAML::Node Lookup(const std::string& key);
  template <typename T>
  void Read(const std::string& key, const YAML::Node& value, T& out, const Check<T>& check);

  YAML::Node node_;
  std::shared_ptr<State> state_;
  std::string path_;
  std::set<std::string> used_;
  bool not_a_mapping_ = false;
};

// Checks for the common cases.
[[nodiscard]] YamlReader::Check<double> Positive();
[[nodiscard]] YamlReader::Check<double> NonNegative();
[[nodiscard]] YamlReader::Check<double> InRange(double lo, double hi);
[[nodiscard]] YamlReader::Check<int> PositiveInt();
[[nodiscard]] YamlReader::Check<int> IntInRange(int lo, int hi);
[[nodiscard]] YamlReader::Check<std::string> OneOf(std::vector<std::string> choices);
/// A name or a path: "" names nothing, so it is refused rather than taken as "none given".
[[nodiscard]] YamlReader::Check<std::string> NonEmpty();
/// Names land in reports: 1 to kMaxNameBytes bytes.
inline constexpr std::size_t kMaxNameBytes = 200;
[[nodiscard]] YamlReader::Check<std::string> Name();

}  // namespace sonarbench
