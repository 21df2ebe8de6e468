// The `compare` section: the variants of `finecap compare`, each checked against the schema of a
// config of its own when the file is read, so that a wrong key fails before any work starts.
#include <algorithm>
#include <cctype>
#include <set>

#include <yaml-cpp/yaml.h>

#include "finecap/config/config.h"
#include "finecap/util/error.h"

namespace finecap {
namespace {

// Folder-safe: a variant's name becomes the name of its output folder.
bool IsValidVariantName(const std::string& name) {
  if (name.empty() || name.front() == '.') return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.';
  });
}

std::string ValueText(const YAML::Node& value) {
  if (value.IsScalar()) return value.Scalar();
  YAML::Emitter flow;
  flow << YAML::Flow << value;
  return flow.c_str();
}

// The settings of a `set` mapping as (dotted path, value text), nested sections flattened.
void FlattenSettings(const YAML::Node& mapping, const std::string& prefix, const std::string& where,
                     std::vector<std::pair<std::string, std::string>>* settings) {
  for (const auto& entry : mapping) {
    const std::string path = prefix + entry.first.as<std::string>();
    if (entry.second.IsMap()) {
      FlattenSettings(entry.second, path + ".", where, settings);
      continue;
    }
    Require(entry.second.IsDefined() && !entry.second.IsNull(), where,
            "key '" + path + "' has no value");
    settings->push_back({path, ValueText(entry.second)});
  }
}

CompareVariant ParseVariant(const YAML::Node& item, int index, const std::string& where) {
  const std::string item_where = where + ", variant " + std::to_string(index + 1);
  Require(item.IsMap(), item_where, "expected a mapping with `name` and `set`");
  for (const auto& entry : item) {
    const std::string field = entry.first.as<std::string>();
    Require(field == "name" || field == "set", item_where,
            "unknown field '" + field + "' (a variant has `name` and `set`)");
  }
  const YAML::Node name = item["name"];
  Require(name.IsDefined() && name.IsScalar(), item_where, "has no `name`");
  CompareVariant variant;
  variant.name = name.Scalar();
  variant.source = where + ", variant '" + variant.name + "'";
  Require(IsValidVariantName(variant.name), variant.source,
          "a name may hold letters, digits, '_', '-' and '.' and may not start with '.'");
  const YAML::Node set = item["set"];
  if (set.IsDefined() && !set.IsNull()) {
    Require(set.IsMap(), variant.source,
            "`set` must map config keys to values, e.g. {solver.type: lbfgs}");
    FlattenSettings(set, "", variant.source, &variant.settings);
  }
  return variant;
}

// Applies the settings of `variant` in order to the config bound to `schema`.
void ApplySettings(const CompareVariant& variant, ConfigSchema* schema) {
  for (const auto& [path, value] : variant.settings) {
    Require(!IsSharedComparisonKey(path), variant.source + ": key '" + path + "'",
            "all variants share the capture, output.dir and the compare section; a variant "
            "cannot set them");
    schema->Set(path, value, variant.source);
  }
}

// Applies the settings to a config of defaults: unknown keys, wrong types and out-of-range
// values fail here, naming the variant. Cross-key checks wait for VariantConfig.
void CheckSettings(const CompareVariant& variant) {
  Config scratch;
  ConfigSchema schema = MakeConfigSchema(&scratch);
  ApplySettings(variant, &schema);
}

std::string VariantNames(const std::vector<CompareVariant>& variants) {
  std::string names;
  for (const CompareVariant& variant : variants)
    names += (names.empty() ? "" : ", ") + variant.name;
  return "[" + names + "]";
}

}  // namespace

bool IsSharedComparisonKey(const std::string& path) {
  return path.rfind("capture.", 0) == 0 || path.rfind("compare.", 0) == 0 || path == "output.dir";
}

void CompareConfig::Check() const {
  std::set<std::string> names;
  for (const CompareVariant& variant : variants) {
    Require(names.insert(variant.name).second, "compare.variants",
            "two variants are named '" + variant.name + "'");
  }
  Require(reference.empty() || names.count(reference) > 0, "compare.reference",
          "'" + reference + "' is not the name of a variant " + VariantNames(variants));
}

void AddCompareKeys(CompareConfig* compare, ConfigSchema* schema) {
  schema->AddCustom(
      "compare.variants", "list of variants", "",
      "finecap compare: the variants to run, each {name: NAME, set: {key: value, ...}}; see "
      "docs/usage.md.",
      [compare](const YAML::Node& value, const std::string& where) {
        Require(value.IsSequence(), where,
                "expected a list of variants such as [{name: a, set: {solver.type: lbfgs}}]");
        std::vector<CompareVariant> variants;
        for (size_t i = 0; i < value.size(); ++i) {
          variants.push_back(ParseVariant(value[i], static_cast<int>(i), where));
          CheckSettings(variants.back());
        }
        compare->variants = variants;
      },
      [compare] { return VariantNames(compare->variants); });
  schema->AddString("compare.reference", &compare->reference,
                    "finecap compare: the variant whose time per frame the others' are divided "
                    "by; \"\" = the first gradient_ascent variant, else the first.");
}

Config VariantConfig(const Config& base, const CompareVariant& variant) {
  Config config = base;
  ConfigSchema schema = MakeConfigSchema(&config);
  ApplySettings(variant, &schema);
  config.refine.solver.num_threads = config.runtime.threads;
  CheckConfig(config, variant.source);
  return config;
}

}  // namespace finecap
