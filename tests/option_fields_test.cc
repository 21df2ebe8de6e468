// The declaration of an options struct's fields (option_fields.h): what it records, what
// CheckValues refuses and how it names the field, what a visitor sees, and the keys the config
// schema makes of it.
#include "finecap/util/option_fields.h"

#include <limits>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "finecap/config/config_schema.h"
#include "finecap/util/error.h"
#include "test_util.h"

namespace finecap {

enum class Shade { kLight, kDark };
const std::vector<EnumName<Shade>>& EnumNames(Shade) {
  static const std::vector<EnumName<Shade>> names = {{Shade::kLight, "light"},
                                                     {Shade::kDark, "dark"}};
  return names;
}

namespace {

using testing_util::ExpectErrorMentions;

struct Inner {
  double weight = 0.5;

  static const OptionFields<Inner>& Fields() {
    static const OptionFields<Inner> fields = [] {
      OptionFields<Inner> f;
      f.AddDouble("weight", &Inner::weight, "A weight.", 0.0, 1.0);
      return f;
    }();
    return fields;
  }
};

struct Toy {
  int rings = 2;
  int samples = 0;
  double scale = 1.5;
  double offset = 0.0;
  bool enabled = true;
  Shade shade = Shade::kLight;
  std::string label = "toy";
  std::vector<double> heights = {0.5};
  Inner inner;

  static const OptionFields<Toy>& Fields() {
    static const OptionFields<Toy> fields = [] {
      OptionFields<Toy> f;
      f.AddInt("rings", &Toy::rings, "Rings.", 1, 10);
      f.AddIntOrOff("samples", &Toy::samples, "Samples; 0 = off.", 3, 100);
      f.AddDouble("scale", &Toy::scale, "Scale.", 1.0, 4.0);
      f.AddDouble("offset", &Toy::offset, "Offset, any finite number.");
      f.AddBool("enabled", &Toy::enabled, "Enabled.");
      f.AddEnum("shade", &Toy::shade, "Shade.");
      f.AddString("label", &Toy::label, "Label.");
      f.AddDoubleList("heights", &Toy::heights, "Heights.", -1.0, 1.0);
      f.AddSection("inner", &Toy::inner, Inner::Fields());
      f.AddCustom("seed", "A seed the config reads itself.", 0.0, 9.0);
      return f;
    }();
    return fields;
  }
};

// The problem of the first field that Toy::Fields() refuses in `toy`, prefixed with the field.
std::string Refusal(const Toy& toy) {
  try {
    Toy::Fields().CheckValues(toy, "Toy::");
  } catch (const Error& error) {
    return error.where() + ": " + error.problem();
  }
  return "";
}

TEST(OptionFieldsTest, RecordsEachFieldInDeclarationOrder) {
  const std::vector<OptionField> fields = Toy::Fields().Declared();
  std::vector<std::string> names;
  for (const OptionField& field : fields) names.push_back(field.name);
  EXPECT_EQ(names, (std::vector<std::string>{"rings", "samples", "scale", "offset", "enabled",
                                             "shade", "label", "heights", "inner", "seed"}));
  const OptionField& rings = Toy::Fields().Field("rings");
  EXPECT_EQ(rings.type, OptionField::Type::kInt);
  EXPECT_EQ(rings.doc, "Rings.");
  EXPECT_EQ(rings.min, 1.0);
  EXPECT_EQ(rings.max, 10.0);
  EXPECT_TRUE(Toy::Fields().Field("samples").zero_also);
  const OptionField& offset = Toy::Fields().Field("offset");
  EXPECT_FALSE(offset.HasMin());
  EXPECT_FALSE(offset.HasMax());
  EXPECT_EQ(Toy::Fields().Field("shade").choices, (std::vector<std::string>{"light", "dark"}));
  EXPECT_EQ(Toy::Fields().Field("seed").max, 9.0);
  EXPECT_THROW(Toy::Fields().Field("no_such_field"), std::invalid_argument);
}

TEST(OptionFieldsTest, CheckValuesTakesValuesInsideTheDeclaredRanges) {
  Toy toy;
  EXPECT_EQ(Refusal(toy), "");
  toy.rings = 10;
  toy.samples = 3;
  toy.scale = 1.0;
  toy.offset = -1e300;
  toy.heights = {-1.0, 1.0};
  toy.inner.weight = 7.0;  // A section is its own struct's to check.
  EXPECT_EQ(Refusal(toy), "");
}

TEST(OptionFieldsTest, CheckValuesNamesTheFieldAndItsRange) {
  Toy toy;
  toy.rings = 11;
  EXPECT_EQ(Refusal(toy), "Toy::rings: is 11 but must lie in [1, 10]");
  toy = Toy();
  toy.samples = 2;
  EXPECT_EQ(Refusal(toy), "Toy::samples: is 2 but must be 0 (off) or lie in [3, 100]");
  toy = Toy();
  toy.scale = 0.99;
  EXPECT_EQ(Refusal(toy), "Toy::scale: is 0.99 but must lie in [1, 4]");
  toy = Toy();
  toy.offset = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(Refusal(toy), "Toy::offset: must be a finite number");
  toy = Toy();
  toy.shade = static_cast<Shade>(7);
  EXPECT_EQ(Refusal(toy), "Toy::shade: is not a valid choice (value 7)");
  toy = Toy();
  toy.heights = {0.0, 2.0};
  EXPECT_EQ(Refusal(toy), "Toy::heights: is 2 but must lie in [-1, 1]");
}

// Records what a visitor sees: each field's path and its value as text.
class Recorder : public OptionFieldVisitor {
 public:
  void Int(const OptionField& field, int* value) override { Record(field, std::to_string(*value)); }
  void Double(const OptionField& field, double* value) override {
    Record(field, std::to_string(*value));
  }
  void Choice(const OptionField& field, std::function<void(const std::string&)> set,
              std::function<std::string()> get) override {
    set("dark");
    Record(field, get());
  }
  void Custom(const OptionField& field) override { Record(field, "custom"); }
  void BeginSection(const OptionField& field) override { section_ = field.name + "."; }
  void EndSection() override { section_.clear(); }

  std::vector<std::string> seen;

 private:
  void Record(const OptionField& field, const std::string& value) {
    seen.push_back(section_ + field.name + "=" + value);
  }
  std::string section_;
};

TEST(OptionFieldsTest, AVisitorReachesTheFieldsOfTheObject) {
  Toy toy;
  Recorder recorder;
  Toy::Fields().Visit(&toy, &recorder);
  EXPECT_EQ(recorder.seen,
            (std::vector<std::string>{"rings=2", "samples=0", "scale=1.500000", "offset=0.000000",
                                      "shade=dark", "inner.weight=0.500000", "seed=custom"}));
  EXPECT_EQ(toy.shade, Shade::kDark);  // The visitor wrote through the field's setter.
}

TEST(OptionFieldsTest, TheSchemaMakesAKeyOfEachFieldWithItsDeclaration) {
  Toy toy;
  ConfigSchema schema;
  int seed = 4;
  schema.AddFields("toy.", &toy, Toy::Fields(),
                   {{"seed", [&](const std::string& path, const OptionField& field) {
                       schema.AddInt(path, &seed, field.doc + " (made by the caller)");
                     }}});
  EXPECT_EQ(schema.HelpText("toy.rings"), "  toy.rings (int [1, 10], default 2)\n      Rings.\n");
  EXPECT_NE(schema.HelpText("toy.samples").find("int 0 or [3, 100]"), std::string::npos);
  EXPECT_NE(schema.HelpText("toy.shade").find("choice light, dark"), std::string::npos);
  EXPECT_NE(
      schema.HelpText("toy.seed").find("A seed the config reads itself. (made by the caller)"),
      std::string::npos);
  schema.Set("toy.inner.weight", "0.25", "--set");
  EXPECT_EQ(toy.inner.weight, 0.25);
  schema.Set("toy.heights", "[0.1, -0.2]", "--set");
  EXPECT_EQ(toy.heights, (std::vector<double>{0.1, -0.2}));
  ExpectErrorMentions([&] { schema.Set("toy.scale", "5", "--set"); },
                      {"key 'toy.scale'", "value 5 is outside [1, 4]"});
}

TEST(OptionFieldsTest, TheSchemaRefusesACustomFieldWithoutItsMakerAndAMakerWithoutAField) {
  Toy toy;
  ConfigSchema schema;
  ExpectErrorMentions([&] { schema.AddFields("toy.", &toy, Toy::Fields()); },
                      {"toy.seed", "a custom option field without a key maker"});
  ConfigSchema other;
  const ConfigSchema::FieldKeyMaker nothing = [](const std::string&, const OptionField&) {};
  ExpectErrorMentions(
      [&] {
        other.AddFields("toy.", &toy, Toy::Fields(), {{"seed", nothing}, {"sede", nothing}});
      },
      {"toy.sede", "a special key maker for a field that is not declared"});
}

}  // namespace
}  // namespace finecap
