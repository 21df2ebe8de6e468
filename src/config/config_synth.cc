// The keys of section `synth`: every field of SynthOptions, as SynthOptions::Fields() declares it.
//
// Most keys are plain numbers, flags and choices. The custom fields need their own parsing, done
// here through ConfigSchema::AddCustom: the 64-bit seeds, lists of a fixed length (lens
// distortion, colours, a light direction) and the list of fold families, whose items are mappings
// of FoldComponent's declared fields.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include <yaml-cpp/yaml.h>

#include "finecap/config/config.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

constexpr double kNoMin = std::numeric_limits<double>::lowest();
constexpr double kNoMax = std::numeric_limits<double>::max();

// The schema names a key as "<file>: key '<path>'". A part of a value (a fold's field) goes
// inside the quotes, so that its errors read like those of any other key.
std::string SubKeyWhere(const std::string& where, const std::string& suffix) {
  if (!where.empty() && where.back() == '\'') {
    return where.substr(0, where.size() - 1) + suffix + "'";
  }
  return where + suffix;
}

// The shortest decimal text that reads back as exactly `value` ("0.16", not "0.16000000000000001").
std::string NumberText(double value) {
  for (int precision : {15, std::numeric_limits<double>::max_digits10}) {
    std::ostringstream text;
    text.precision(precision);
    text << value;
    if (std::stod(text.str()) == value) return text.str();
  }
  return YAML::Node(value).as<std::string>();
}

std::string RangeText(double min, double max) {
  if (min == kNoMin && max == kNoMax) return "";
  if (max == kNoMax) return ">= " + NumberText(min);
  if (min == kNoMin) return "<= " + NumberText(max);
  return "[" + NumberText(min) + ", " + NumberText(max) + "]";
}

std::string ListText(const double* values, int size) {
  std::string text = "[";
  for (int i = 0; i < size; ++i) text += (i ? ", " : "") + NumberText(values[i]);
  return text + "]";
}

std::string ScalarText(const YAML::Node& value, const std::string& where) {
  Require(!value.IsNull(), where, "the value is missing");
  Require(value.IsScalar(), where, "expected a single value, found a list or mapping");
  return value.Scalar();
}

double ParseNumber(const YAML::Node& value, const std::string& where, double min, double max) {
  const std::string text = ScalarText(value, where);
  double number = 0.0;
  Require(YAML::convert<double>::decode(value, number), where,
          "expected a number, got '" + text + "'");
  Require(std::isfinite(number), where, "value must be finite");
  Require(number >= min && number <= max, where,
          "value " + text + " is outside " + RangeText(min, max));
  return number;
}

std::string ParseChoice(const YAML::Node& value, const std::string& where,
                        const std::vector<std::string>& choices) {
  const std::string text = ScalarText(value, where);
  std::string listed;
  for (const std::string& choice : choices) {
    if (choice == text) return text;
    listed += (listed.empty() ? "" : ", ") + choice;
  }
  throw Error(where, "'" + text + "' is not one of: " + listed);
}

// A list of exactly `size` numbers in [min, max], written to values[0 .. size-1]; the field is
// left untouched unless the whole list is valid.
void AddFixedList(ConfigSchema* schema, const std::string& path, double* values, int size,
                  const std::string& doc, double min = kNoMin, double max = kNoMax) {
  const std::string range = RangeText(min, max);
  schema->AddCustom(
      path, "list of " + std::to_string(size) + " floats", range, doc,
      [=](const YAML::Node& value, const std::string& where) {
        Require(value.IsSequence(), where,
                "expected a list of " + std::to_string(size) + " numbers such as " +
                    ListText(values, size));
        Require(static_cast<int>(value.size()) == size, where,
                "expected exactly " + std::to_string(size) + " numbers, got " +
                    std::to_string(value.size()));
        std::vector<double> numbers;
        for (const YAML::Node& item : value) numbers.push_back(ParseNumber(item, where, min, max));
        std::copy(numbers.begin(), numbers.end(), values);
      },
      [=] { return ListText(values, size); });
}

// Seeds are 64-bit unsigned: an int key would cut their range in half.
void AddSeed(ConfigSchema* schema, const std::string& path, std::uint64_t* field,
             const std::string& doc) {
  schema->AddCustom(
      path, "uint64", "[0, 2^64 - 1]", doc,
      [=](const YAML::Node& value, const std::string& where) {
        const std::string text = ScalarText(value, where);
        std::uint64_t seed = 0;
        Require(YAML::convert<std::uint64_t>::decode(value, seed), where,
                "expected an integer in [0, 2^64 - 1], got '" + text + "'");
        *field = seed;
      },
      [=] { return std::to_string(*field); });
}

// ---- Folds ----

// Reads the key `name` of a fold mapping into the field of that name (FoldComponent::Fields()).
class FoldFieldReader : public OptionFieldVisitor {
 public:
  FoldFieldReader(std::string name, YAML::Node value, std::string where)
      : name_(std::move(name)), value_(std::move(value)), where_(std::move(where)) {}

  void Double(const OptionField& field, double* number) override {
    if (Claim(field)) *number = ParseNumber(value_, where_, field.min, field.max);
  }
  void Choice(const OptionField& field, std::function<void(const std::string&)> set,
              std::function<std::string()>) override {
    if (Claim(field)) set(ParseChoice(value_, where_, field.choices));
  }
  bool found() const { return found_; }

 private:
  bool Claim(const OptionField& field) {
    found_ = found_ || field.name == name_;
    return field.name == name_;
  }

  const std::string name_;
  const YAML::Node value_;
  const std::string where_;
  bool found_ = false;
};

// Writes a fold's fields as YAML flow entries, "amplitude: 0.008, ..., profile: sine".
class FoldFieldWriter : public OptionFieldVisitor {
 public:
  void Double(const OptionField& field, double* number) override {
    Append(field.name + ": " + NumberText(*number));
  }
  void Choice(const OptionField& field, std::function<void(const std::string&)>,
              std::function<std::string()> get) override {
    Append(field.name + ": " + get());
  }
  const std::string& text() const { return text_; }

 private:
  void Append(const std::string& entry) { text_ += (text_.empty() ? "" : ", ") + entry; }
  std::string text_;
};

std::string FoldKeys() {
  std::string keys;
  for (const OptionField& field : FoldComponent::Fields().Declared()) {
    keys += (keys.empty() ? "" : ", ") + field.name;
  }
  return keys;
}

// One item of `folds`: a mapping of some of the fold keys; absent keys keep their defaults.
FoldComponent ParseFold(const YAML::Node& item, const std::string& where) {
  Require(item.IsMap(), where, "expected a mapping such as {amplitude: 0.008, wavelength: 0.12}");
  FoldComponent fold;
  for (const auto& entry : item) {
    const std::string name = ScalarText(entry.first, where);
    FoldFieldReader reader(name, entry.second, SubKeyWhere(where, "." + name));
    FoldComponent::Fields().Visit(&fold, &reader);
    Require(reader.found(), SubKeyWhere(where, "." + name),
            "unknown fold key (known: " + FoldKeys() + ")");
  }
  return fold;
}

std::vector<FoldComponent> ParseFolds(const YAML::Node& value, const std::string& where) {
  Require(value.IsSequence(), where,
          "expected a list of fold mappings such as [{amplitude: 0.008, wavelength: 0.12}]");
  std::vector<FoldComponent> folds;
  for (const YAML::Node& item : value) {
    const std::string index = "[" + std::to_string(folds.size()) + "]";
    folds.push_back(ParseFold(item, SubKeyWhere(where, index)));
  }
  return folds;
}

// YAML flow syntax, e.g. [{amplitude: 0.008, wavelength: 0.12, ..., profile: sine}].
std::string FoldsText(std::vector<FoldComponent> folds) {
  std::string text = "[";
  for (size_t i = 0; i < folds.size(); ++i) {
    FoldFieldWriter writer;
    FoldComponent::Fields().Visit(&folds[i], &writer);
    text += (i ? ", {" : "{") + writer.text() + "}";
  }
  return text + "]";
}

// ---- Keys of their own ----

ConfigSchema::FieldKeyMaker FoldsKey(std::vector<FoldComponent>* folds, ConfigSchema* schema) {
  return [=](const std::string& path, const OptionField& field) {
    schema->AddCustom(
        path, "list of folds", "{" + FoldKeys() + "}", field.doc,
        [folds](const YAML::Node& value, const std::string& where) {
          *folds = ParseFolds(value, where);
        },
        [folds] { return FoldsText(*folds); });
  };
}

ConfigSchema::FieldKeyMaker FixedListKey(double* values, int size, ConfigSchema* schema) {
  return [=](const std::string& path, const OptionField& field) {
    AddFixedList(schema, path, values, size, field.doc, field.min, field.max);
  };
}

ConfigSchema::FieldKeyMaker SeedKey(std::uint64_t* seed, ConfigSchema* schema) {
  return [=](const std::string& path, const OptionField& field) {
    AddSeed(schema, path, seed, field.doc);
  };
}

}  // namespace

void AddSynthKeys(SynthOptions* options, ConfigSchema* schema) {
  RigOptions& cameras = options->cameras;
  RenderOptions& render = options->render;
  schema->AddFields(
      "synth.", options, SynthOptions::Fields(),
      {{"folds", FoldsKey(&options->folds, schema)},
       {"texture.textureless_color",
        FixedListKey(options->texture.textureless_color.data(), 3, schema)},
       {"cameras.distortion", FixedListKey(cameras.distortion.data(),
                                           static_cast<int>(cameras.distortion.size()), schema)},
       {"render.light_direction", FixedListKey(render.light_direction.data(), 3, schema)},
       {"render.background", FixedListKey(render.background.data(), 3, schema)},
       {"render.noise_seed", SeedKey(&render.noise_seed, schema)},
       {"seed", SeedKey(&options->seed, schema)}});
}

}  // namespace finecap
