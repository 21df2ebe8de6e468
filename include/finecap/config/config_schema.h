// A typed, documented schema of configuration keys, bound to the fields of options structs.
//
// Every key has a dot-separated path ("solver.max_iterations"), a type, a documentation line, an
// allowed range or set of choices, and the field it writes. Reading a YAML file against the schema
// refuses unknown keys, wrong types and out-of-range values with an Error naming the file and the
// key path; an override ("key=value", from the command line) goes through the same checks. The
// schema also prints itself, so `--help` and docs/configuration.md list every key with its default.
#ifndef FINECAP_CONFIG_CONFIG_SCHEMA_H_
#define FINECAP_CONFIG_CONFIG_SCHEMA_H_

#include <functional>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "finecap/util/enum_names.h"
#include "finecap/util/option_fields.h"

namespace YAML {
class Node;
}

namespace finecap {

class ConfigSchema {
 public:
  // Registers a key bound to `*field`, whose current value is the key's default. Numeric keys
  // accept values in [min, max]; choice keys one of `choices`. A path must be unique.
  void AddInt(const std::string& path, int* field, const std::string& doc,
              int min = std::numeric_limits<int>::lowest(),
              int max = std::numeric_limits<int>::max());
  void AddDouble(const std::string& path, double* field, const std::string& doc,
                 double min = std::numeric_limits<double>::lowest(),
                 double max = std::numeric_limits<double>::max());
  // A number in [min, max] or the word "auto": a number sets `*field` and clears `*is_auto`,
  // "auto" sets `*is_auto` (and leaves `*field`). Prints as "auto" while `*is_auto` is set.
  void AddDoubleOrAuto(const std::string& path, double* field, bool* is_auto,
                       const std::string& doc, double min, double max);
  void AddBool(const std::string& path, bool* field, const std::string& doc);
  void AddString(const std::string& path, std::string* field, const std::string& doc);
  void AddChoice(const std::string& path, std::string* field, const std::string& doc,
                 const std::vector<std::string>& choices);
  // A choice bound to an enum: the allowed values are the names of its table (enum_names.h).
  template <typename Enum>
  void AddEnum(const std::string& path, Enum* field, const std::string& doc) {
    AddChoiceKey(
        path, doc, EnumNameList<Enum>(),
        [field](const std::string& name) { StringToEnum(name, field); },
        [field] { return EnumToString(*field); });
  }
  // An integer that is 0 (the feature is off) or lies in [min, max].
  void AddIntOrOff(const std::string& path, int* field, const std::string& doc, int min, int max);
  void AddDoubleList(const std::string& path, std::vector<double>* field, const std::string& doc,
                     double min = std::numeric_limits<double>::lowest(),
                     double max = std::numeric_limits<double>::max());

  // Makes the key of a declared field that needs handling of its own (a custom field, a length
  // that may be "auto"), from the key's full path and the field's declaration.
  using FieldKeyMaker = std::function<void(const std::string& path, const OptionField& field)>;
  // A key for every field that `fields` declares of `*object`, in declaration order, at `prefix`
  // followed by the field's name ("energy." + "w_reg"; a section's fields below its name), with
  // the declared doc and range. `special` makes the keys of the fields it names (relative to
  // `prefix`, e.g. "consensus.passes") instead; it must name every custom field and no field
  // that is not declared.
  template <typename Options>
  void AddFields(const std::string& prefix, Options* object, const OptionFields<Options>& fields,
                 const std::map<std::string, FieldKeyMaker>& special = {}) {
    AddFieldKeys(
        prefix, [object, &fields](OptionFieldVisitor* visitor) { fields.Visit(object, visitor); },
        special);
  }

  // An int key bound to `*field` (the config's own copy of a library field) with the range and doc
  // that `declared` states.
  void AddDeclaredInt(const std::string& path, int* field, const OptionField& declared);

  // A key of any other type: `assign` parses and checks a YAML value and writes the field,
  // throwing Error(where, problem) on failure; `current_text` prints the field as YAML.
  void AddCustom(const std::string& path, const std::string& type, const std::string& range,
                 const std::string& doc,
                 std::function<void(const YAML::Node& value, const std::string& where)> assign,
                 std::function<std::string()> current_text);

  // A former name of key `path` (which must be registered), still read and set as `path` so
  // that older configs keep working; help and docs/configuration.md list it as such.
  void AddAlias(const std::string& old_path, const std::string& path);

  // Reads a YAML file into the bound fields. Keys absent from the file keep their values.
  void ReadFile(const std::string& file);
  // Reads an already parsed document; `file` names it in errors.
  void ReadNode(const YAML::Node& root, const std::string& file);
  // Sets one key from text (YAML syntax for the value), e.g. Set("solver.max_iterations", "50").
  // `source` names where the override came from, for errors (e.g. "--set").
  void Set(const std::string& path, const std::string& value, const std::string& source);

  bool Has(const std::string& path) const;
  // The value of a key in YAML syntax, as it is now.
  std::string ValueText(const std::string& path) const;

  // A numeric key (int or float, not an alias) with its allowed range, and a way to write its
  // field past that range: for tests that hold the options structs' Check()s to the schema.
  struct NumericKey {
    std::string path;
    bool is_integer = false;
    // The bounds; the type's lowest() / max() when a side is unbounded.
    double min = 0.0;
    double max = 0.0;
    bool zero_also = false;  // 0 is allowed outside [min, max] too (AddIntOrOff).
    std::function<void(double)> write_unchecked;
  };
  std::vector<NumericKey> NumericKeys() const;

  // One line per key below `prefix` ("" for all): path, type, default, range, documentation.
  std::string HelpText(const std::string& prefix = "") const;
  // A Markdown table of all keys: docs/configuration.md (checked by tests/docs_test.cc).
  std::string MarkdownTable() const;

 private:
  class FieldKeyAdder;

  struct Key {
    std::string path;
    std::string type;   // "int", "float", "bool", "string", "choice", "list of float".
    std::string range;  // Human-readable allowed values; may be empty.
    std::string doc;
    std::string default_text;
    // Parses and checks a YAML value, then writes the field; throws Error(where, ...) on failure.
    std::function<void(const YAML::Node& value, const std::string& where)> assign;
    std::function<std::string()> current_text;
    std::string alias_of;  // For a former name: the key it stands for.
    // Numeric keys only: the range, and a writer of the field that skips its checks.
    bool is_numeric = false;
    double min = 0.0;
    double max = 0.0;
    bool zero_also = false;
    std::function<void(double)> write_unchecked;
  };

  static Key MakeKey(const std::string& path, const std::string& type, const std::string& range,
                     const std::string& doc,
                     std::function<void(const YAML::Node& value, const std::string& where)> assign,
                     std::function<std::string()> current_text);
  void AddKey(Key key);
  template <typename T>
  static void SetNumeric(T min, T max, std::function<void(double)> write_unchecked, Key* key);
  void AddChoiceKey(const std::string& path, const std::string& doc,
                    const std::vector<std::string>& choices,
                    std::function<void(const std::string&)> set,
                    std::function<std::string()> current_text);
  void AddFieldKeys(const std::string& prefix,
                    const std::function<void(OptionFieldVisitor*)>& visit_fields,
                    const std::map<std::string, FieldKeyMaker>& special);
  const Key* Find(const std::string& path) const;
  void ReadMapping(const YAML::Node& mapping, const std::string& prefix, const std::string& file);

  std::vector<Key> keys_;
};

}  // namespace finecap

#endif  // FINECAP_CONFIG_CONFIG_SCHEMA_H_
