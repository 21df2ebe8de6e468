#include "finecap/config/config_schema.h"

#include <cmath>
#include <set>
#include <sstream>

#include <yaml-cpp/yaml.h>

#include "finecap/util/error.h"

namespace finecap {
namespace {

std::string KeyWhere(const std::string& file, const std::string& path) {
  return file + ": key '" + path + "'";
}

std::string Scalar(const YAML::Node& value, const std::string& where) {
  Require(value.IsScalar(), where, "expected a single value, found a list or mapping");
  return value.Scalar();
}

template <typename T>
T Convert(const YAML::Node& value, const std::string& where, const std::string& type_name) {
  const std::string text = Scalar(value, where);
  try {
    return value.as<T>();
  } catch (const YAML::Exception&) {
    throw Error(where, "expected " + type_name + ", got '" + text + "'");
  }
}

template <typename T>
std::string RangeText(T min, T max) {
  const bool has_min = min != std::numeric_limits<T>::lowest();
  const bool has_max = max != std::numeric_limits<T>::max();
  std::ostringstream text;
  if (has_min && has_max) {
    text << "[" << min << ", " << max << "]";
  } else if (has_min) {
    text << ">= " << min;
  } else if (has_max) {
    text << "<= " << max;
  }
  return text.str();
}

template <typename T>
void RequireInRange(T value, T min, T max, const std::string& where) {
  Require(value >= min && value <= max, where,
          "value " + YAML::Node(value).as<std::string>() + " is outside " + RangeText(min, max));
}

double ConvertDouble(const YAML::Node& value, const std::string& where) {
  const double number = Convert<double>(value, where, "a number");
  Require(std::isfinite(number), where, "value must be finite");
  return number;
}

std::string Join(const std::vector<std::string>& items, const std::string& separator) {
  std::string joined;
  for (const std::string& item : items) joined += (joined.empty() ? "" : separator) + item;
  return joined;
}

// The shortest text that reads back as the same double's neighbourhood: 0.05, not
// 0.050000000000000003 (yaml-cpp writes 17 significant digits).
std::string DoubleText(double value) {
  std::ostringstream text;
  text.precision(15);
  text << value;
  return text.str();
}

std::string DoubleListText(const std::vector<double>& values) {
  std::ostringstream text;
  text << "[";
  for (size_t i = 0; i < values.size(); ++i) text << (i ? ", " : "") << values[i];
  text << "]";
  return text.str();
}

}  // namespace

ConfigSchema::Key ConfigSchema::MakeKey(
    const std::string& path, const std::string& type, const std::string& range,
    const std::string& doc,
    std::function<void(const YAML::Node& value, const std::string& where)> assign,
    std::function<std::string()> current_text) {
  Key key;
  key.path = path;
  key.type = type;
  key.range = range;
  key.doc = doc;
  key.assign = std::move(assign);
  key.current_text = std::move(current_text);
  return key;
}

template <typename T>
void ConfigSchema::SetNumeric(T min, T max, std::function<void(double)> write_unchecked, Key* key) {
  key->is_numeric = true;
  key->min = static_cast<double>(min);
  key->max = static_cast<double>(max);
  key->write_unchecked = std::move(write_unchecked);
}

void ConfigSchema::AddKey(Key key) {
  Require(Find(key.path) == nullptr, key.path, "config key registered twice");
  key.default_text = key.current_text();
  keys_.push_back(std::move(key));
}

const ConfigSchema::Key* ConfigSchema::Find(const std::string& path) const {
  for (const Key& key : keys_) {
    if (key.path == path) return &key;
  }
  return nullptr;
}

bool ConfigSchema::Has(const std::string& path) const { return Find(path) != nullptr; }

void ConfigSchema::AddInt(const std::string& path, int* field, const std::string& doc, int min,
                          int max) {
  Key key = MakeKey(
      path, "int", RangeText(min, max), doc,
      [=](const YAML::Node& value, const std::string& where) {
        const int number = Convert<int>(value, where, "an integer");
        RequireInRange(number, min, max, where);
        *field = number;
      },
      [=] { return std::to_string(*field); });
  SetNumeric(
      min, max, [=](double value) { *field = static_cast<int>(value); }, &key);
  AddKey(std::move(key));
}

void ConfigSchema::AddIntOrOff(const std::string& path, int* field, const std::string& doc, int min,
                               int max) {
  Key key = MakeKey(
      path, "int", "0 or " + RangeText(min, max), doc,
      [=](const YAML::Node& value, const std::string& where) {
        const int number = Convert<int>(value, where, "an integer");
        Require(number == 0 || (number >= min && number <= max), where,
                "value " + std::to_string(number) + " is neither 0 (off) nor in " +
                    RangeText(min, max));
        *field = number;
      },
      [=] { return std::to_string(*field); });
  SetNumeric(
      min, max, [=](double value) { *field = static_cast<int>(value); }, &key);
  key.zero_also = true;
  AddKey(std::move(key));
}

void ConfigSchema::AddDouble(const std::string& path, double* field, const std::string& doc,
                             double min, double max) {
  Key key = MakeKey(
      path, "float", RangeText(min, max), doc,
      [=](const YAML::Node& value, const std::string& where) {
        const double number = ConvertDouble(value, where);
        RequireInRange(number, min, max, where);
        *field = number;
      },
      [=] { return DoubleText(*field); });
  SetNumeric(
      min, max, [=](double value) { *field = value; }, &key);
  AddKey(std::move(key));
}

void ConfigSchema::AddDoubleOrAuto(const std::string& path, double* field, bool* is_auto,
                                   const std::string& doc, double min, double max) {
  Key key = MakeKey(
      path, "float", RangeText(min, max) + " or auto", doc,
      [=](const YAML::Node& value, const std::string& where) {
        if (value.IsScalar() && value.Scalar() == "auto") {
          *is_auto = true;
          return;
        }
        const double number = Convert<double>(value, where, "a number or auto");
        Require(std::isfinite(number), where, "value must be finite");
        RequireInRange(number, min, max, where);
        *field = number;
        *is_auto = false;
      },
      [=] { return *is_auto ? std::string("auto") : DoubleText(*field); });
  SetNumeric(
      min, max,
      [=](double value) {
        *field = value;
        *is_auto = false;
      },
      &key);
  AddKey(std::move(key));
}

void ConfigSchema::AddBool(const std::string& path, bool* field, const std::string& doc) {
  AddKey(MakeKey(
      path, "bool", "true, false", doc,
      [=](const YAML::Node& value, const std::string& where) {
        *field = Convert<bool>(value, where, "true or false");
      },
      [=] { return std::string(*field ? "true" : "false"); }));
}

void ConfigSchema::AddString(const std::string& path, std::string* field, const std::string& doc) {
  AddKey(MakeKey(
      path, "string", "", doc,
      [=](const YAML::Node& value, const std::string& where) { *field = Scalar(value, where); },
      [=] { return *field; }));
}

void ConfigSchema::AddChoiceKey(const std::string& path, const std::string& doc,
                                const std::vector<std::string>& choices,
                                std::function<void(const std::string&)> set,
                                std::function<std::string()> current_text) {
  AddKey(MakeKey(
      path, "choice", Join(choices, ", "), doc,
      [=](const YAML::Node& value, const std::string& where) {
        const std::string text = Scalar(value, where);
        bool known = false;
        for (const std::string& choice : choices) known = known || choice == text;
        Require(known, where, "'" + text + "' is not one of: " + Join(choices, ", "));
        set(text);
      },
      std::move(current_text)));
}

void ConfigSchema::AddChoice(const std::string& path, std::string* field, const std::string& doc,
                             const std::vector<std::string>& choices) {
  AddChoiceKey(
      path, doc, choices, [field](const std::string& text) { *field = text; },
      [field] { return *field; });
}

void ConfigSchema::AddDoubleList(const std::string& path, std::vector<double>* field,
                                 const std::string& doc, double min, double max) {
  AddKey(MakeKey(
      path, "list of float", RangeText(min, max), doc,
      [=](const YAML::Node& value, const std::string& where) {
        Require(value.IsSequence(), where, "expected a list such as [1, 2]");
        std::vector<double> numbers;
        for (const YAML::Node& item : value) {
          numbers.push_back(ConvertDouble(item, where));
          RequireInRange(numbers.back(), min, max, where);
        }
        *field = numbers;
      },
      [=] { return DoubleListText(*field); }));
}

void ConfigSchema::AddCustom(
    const std::string& path, const std::string& type, const std::string& range,
    const std::string& doc,
    std::function<void(const YAML::Node& value, const std::string& where)> assign,
    std::function<std::string()> current_text) {
  AddKey(MakeKey(path, type, range, doc, std::move(assign), std::move(current_text)));
}

void ConfigSchema::AddAlias(const std::string& old_path, const std::string& path) {
  const Key* target = Find(path);
  Require(target != nullptr, old_path, "an alias of a key that is not registered");
  Key alias = *target;
  alias.path = old_path;
  alias.doc = "Former name of `" + path + "`, still accepted.";
  alias.alias_of = path;
  alias.is_numeric = false;
  AddKey(std::move(alias));
}

namespace {

int IntMin(const OptionField& field) {
  return field.HasMin() ? static_cast<int>(field.min) : std::numeric_limits<int>::lowest();
}

int IntMax(const OptionField& field) {
  return field.HasMax() ? static_cast<int>(field.max) : std::numeric_limits<int>::max();
}

}  // namespace

// Adds the key of each field it visits, or leaves it to the caller's maker of special keys.
class ConfigSchema::FieldKeyAdder : public OptionFieldVisitor {
 public:
  FieldKeyAdder(ConfigSchema* schema, const std::string& prefix,
                const std::map<std::string, FieldKeyMaker>& special)
      : schema_(schema), prefixes_{prefix}, special_(special) {}

  void Int(const OptionField& field, int* value) override {
    if (MadeAsSpecial(field)) return;
    if (field.zero_also) {
      schema_->AddIntOrOff(Path(field), value, field.doc, IntMin(field), IntMax(field));
    } else {
      schema_->AddInt(Path(field), value, field.doc, IntMin(field), IntMax(field));
    }
  }
  void Double(const OptionField& field, double* value) override {
    if (MadeAsSpecial(field)) return;
    schema_->AddDouble(Path(field), value, field.doc, field.min, field.max);
  }
  void Bool(const OptionField& field, bool* value) override {
    if (MadeAsSpecial(field)) return;
    schema_->AddBool(Path(field), value, field.doc);
  }
  void String(const OptionField& field, std::string* value) override {
    if (MadeAsSpecial(field)) return;
    schema_->AddString(Path(field), value, field.doc);
  }
  void DoubleList(const OptionField& field, std::vector<double>* value) override {
    if (MadeAsSpecial(field)) return;
    schema_->AddDoubleList(Path(field), value, field.doc, field.min, field.max);
  }
  void Choice(const OptionField& field, std::function<void(const std::string&)> set,
              std::function<std::string()> get) override {
    if (MadeAsSpecial(field)) return;
    schema_->AddChoiceKey(Path(field), field.doc, field.choices, std::move(set), std::move(get));
  }
  void Custom(const OptionField& field) override {
    Require(MadeAsSpecial(field), Path(field), "a custom option field without a key maker");
  }
  void BeginSection(const OptionField& field) override { prefixes_.push_back(Path(field) + "."); }
  void EndSection() override { prefixes_.pop_back(); }

  // Refuses a special key maker for a field that was never visited (a misspelt name).
  void RequireEverySpecialUsed() const {
    for (const auto& special : special_) {
      const std::string& name = special.first;
      Require(used_.count(name) > 0, prefixes_.front() + name,
              "a special key maker for a field that is not declared");
    }
  }

 private:
  std::string Path(const OptionField& field) const { return prefixes_.back() + field.name; }

  bool MadeAsSpecial(const OptionField& field) {
    const std::string path = Path(field);
    const auto special = special_.find(path.substr(prefixes_.front().size()));
    if (special == special_.end()) return false;
    special->second(path, field);
    used_.insert(special->first);
    return true;
  }

  ConfigSchema* schema_;
  std::vector<std::string> prefixes_;  // The first is the caller's; one more per open section.
  const std::map<std::string, FieldKeyMaker>& special_;
  std::set<std::string> used_;
};

void ConfigSchema::AddDeclaredInt(const std::string& path, int* field,
                                  const OptionField& declared) {
  AddInt(path, field, declared.doc, IntMin(declared), IntMax(declared));
}

void ConfigSchema::AddFieldKeys(const std::string& prefix,
                                const std::function<void(OptionFieldVisitor*)>& visit_fields,
                                const std::map<std::string, FieldKeyMaker>& special) {
  FieldKeyAdder adder(this, prefix, special);
  visit_fields(&adder);
  adder.RequireEverySpecialUsed();
}

std::vector<ConfigSchema::NumericKey> ConfigSchema::NumericKeys() const {
  std::vector<NumericKey> numeric;
  for (const Key& key : keys_) {
    if (!key.is_numeric) continue;
    numeric.push_back(
        {key.path, key.type == "int", key.min, key.max, key.zero_also, key.write_unchecked});
  }
  return numeric;
}

void ConfigSchema::ReadFile(const std::string& file) {
  YAML::Node root;
  try {
    root = YAML::LoadFile(file);
  } catch (const YAML::BadFile&) {
    throw Error(file, "cannot open the config file");
  } catch (const YAML::Exception& error) {
    throw Error(file,
                "malformed YAML at line " + std::to_string(error.mark.line + 1) + ": " + error.msg);
  }
  try {
    ReadNode(root, file);
  } catch (const YAML::Exception& error) {
    // A conversion that the checks of each key did not foresee still ends in one Error naming
    // the file.
    throw Error(file, std::string("cannot read the config: ") + error.what());
  }
}

void ConfigSchema::ReadNode(const YAML::Node& root, const std::string& file) {
  if (root.IsNull()) return;  // An empty file changes nothing.
  Require(root.IsMap(), file, "a config must be a mapping of sections to keys");
  ReadMapping(root, "", file);
}

void ConfigSchema::ReadMapping(const YAML::Node& mapping, const std::string& prefix,
                               const std::string& file) {
  for (const auto& entry : mapping) {
    Require(entry.first.IsScalar(), KeyWhere(file, prefix + "..."),
            "a key must be a name, not a list or mapping (line " +
                std::to_string(entry.first.Mark().line + 1) + ")");
    const std::string path = prefix + entry.first.Scalar();
    if (const Key* key = Find(path)) {
      key->assign(entry.second, KeyWhere(file, path));
      continue;
    }
    const bool is_section = entry.second.IsMap() || entry.second.IsNull();
    bool section_known = false;
    for (const Key& key : keys_)
      section_known = section_known || key.path.rfind(path + ".", 0) == 0;
    Require(is_section && section_known, KeyWhere(file, path),
            "unknown key (`finecap --help` lists every key)");
    if (entry.second.IsMap()) ReadMapping(entry.second, path + ".", file);
  }
}

void ConfigSchema::Set(const std::string& path, const std::string& value,
                       const std::string& source) {
  const Key* key = Find(path);
  Require(key != nullptr, KeyWhere(source, path), "unknown key (`finecap --help` lists every key)");
  // Text keys take the value literally ("3:" is a frame range, not a YAML mapping).
  if (key->type == "string" || key->type == "choice") {
    key->assign(YAML::Node(value), KeyWhere(source, path));
    return;
  }
  YAML::Node node;
  try {
    node = YAML::Load(value);
  } catch (const YAML::Exception& error) {
    throw Error(KeyWhere(source, path), "malformed value '" + value + "': " + error.msg);
  }
  key->assign(node, KeyWhere(source, path));
}

std::string ConfigSchema::ValueText(const std::string& path) const {
  const Key* key = Find(path);
  Require(key != nullptr, path, "unknown config key");
  return key->current_text();
}

std::string ConfigSchema::HelpText(const std::string& prefix) const {
  std::ostringstream text;
  for (const Key& key : keys_) {
    if (key.path.rfind(prefix, 0) != 0) continue;
    text << "  " << key.path << " (" << key.type;
    if (!key.range.empty()) text << " " << key.range;
    text << ", default " << (key.default_text.empty() ? "\"\"" : key.default_text) << ")\n";
    text << "      " << key.doc << "\n";
  }
  return text.str();
}

std::string ConfigSchema::MarkdownTable() const {
  std::ostringstream text;
  text << "| key | type | default | allowed | meaning |\n|---|---|---|---|---|\n";
  for (const Key& key : keys_) {
    text << "| `" << key.path << "` | " << key.type << " | `" << key.default_text << "` | "
         << key.range << " | " << key.doc << " |\n";
  }
  return text.str();
}

}  // namespace finecap
