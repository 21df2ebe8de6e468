// The fields of an options struct, each declared once with what a user must know of it.
//
// An options struct's module declares its fields in one place (`EnergyOptions::Fields()`): for each
// field, its key name relative to the struct's section of the config ("w_reg"), its documentation
// line, and its allowed values (a range, or the names of its enum). Everything else reads that
// declaration:
//   * the struct's Check() checks every declared range and choice (CheckValues), naming the C++
//     field ("EnergyOptions::w_reg"), then the rules across fields that it states itself;
//   * the config schema turns each field into a key under the struct's section
//     (ConfigSchema::AddFields), so `finecap --help` and docs/configuration.md print the doc and
//     the range stated here.
// A field's default is its member initialiser: the schema reads the current value.
//
// Fields are declared in the order their keys are listed. A nested options struct is a section
// (AddSection), or a group whose fields share the struct's own section (AddGroup), with a
// declaration and a Check() of its own, which CheckValues leaves to it. A field
// of a type that a declaration does not describe (a list of mappings, a 64-bit seed) is declared
// with AddCustom, its doc and range here, its key made by the config.
#ifndef FINECAP_UTIL_OPTION_FIELDS_H_
#define FINECAP_UTIL_OPTION_FIELDS_H_

#include <functional>
#include <limits>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include "finecap/util/enum_names.h"

namespace finecap {

// What is declared of one field, whatever its type.
struct OptionField {
  enum class Type {
    kInt,
    kDouble,
    kBool,
    kString,
    kChoice,
    kDoubleList,
    kCustom,
    kSection,
    kGroup
  };

  std::string name;  // Relative to the struct's section: "w_reg", "consensus".
  std::string doc;
  Type type = Type::kCustom;
  // Numbers (and the items of a list): the allowed range, the type's lowest() / max() for an
  // unbounded side; `zero_also` allows 0 outside it too (a feature that 0 turns off).
  double min = std::numeric_limits<double>::lowest();
  double max = std::numeric_limits<double>::max();
  bool zero_also = false;
  std::vector<std::string> choices;  // kChoice: the names of the enum's values.

  bool IsNumber() const { return type == Type::kInt || type == Type::kDouble; }
  bool HasMin() const;
  bool HasMax() const;
};

// Receives the fields of one object, each with the address of its value (OptionFields::Visit).
// A visitor overrides the kinds of field it handles; the others pass by.
class OptionFieldVisitor {
 public:
  virtual ~OptionFieldVisitor() = default;
  virtual void Int(const OptionField& /*field*/, int* /*value*/) {}
  virtual void Double(const OptionField& /*field*/, double* /*value*/) {}
  virtual void Bool(const OptionField& /*field*/, bool* /*value*/) {}
  virtual void String(const OptionField& /*field*/, std::string* /*value*/) {}
  virtual void DoubleList(const OptionField& /*field*/, std::vector<double>* /*value*/) {}
  // An enum, read and written by the names of its values.
  virtual void Choice(const OptionField& /*field*/, std::function<void(const std::string&)> /*set*/,
                      std::function<std::string()> /*get*/) {}
  virtual void Custom(const OptionField& /*field*/) {}
  // A nested struct: its fields follow, their names relative to the section's, until EndSection.
  virtual void BeginSection(const OptionField& /*field*/) {}
  virtual void EndSection() {}
};

namespace internal {
// Throw Error(field_name, ...) when a value lies outside what `field` declares.
void CheckDeclaredNumber(double value, const OptionField& field, const std::string& field_name);
// Each of values[0 .. count-1] (a list, a vector of a custom field) against the same declaration.
void CheckDeclaredNumbers(const double* values, int count, const OptionField& field,
                          const std::string& field_name);
void CheckDeclaredChoice(bool known, int value, const std::string& field_name);
}  // namespace internal

// The declared fields of `Options`, in order. A struct declares them once, in a function-local
// static that a section may refer to:
//   const OptionFields<EnergyOptions>& EnergyOptions::Fields() {
//     static const OptionFields<EnergyOptions> fields = [] {
//       OptionFields<EnergyOptions> f;
//       f.AddDouble("w_reg", &EnergyOptions::w_reg, "Weight of the regulariser.", 0.0, 1e12);
//       return f;
//     }();
//     return fields;
//   }
template <typename Options>
class OptionFields {
 public:
  OptionFields& AddInt(const std::string& name, int Options::*member, const std::string& doc,
                       int min = std::numeric_limits<int>::lowest(),
                       int max = std::numeric_limits<int>::max()) {
    return AddNumber(NumberField(name, doc, OptionField::Type::kInt, min, max), member);
  }
  // An integer that is 0 (the feature is off) or lies in [min, max].
  OptionFields& AddIntOrOff(const std::string& name, int Options::*member, const std::string& doc,
                            int min, int max) {
    OptionField field = NumberField(name, doc, OptionField::Type::kInt, min, max);
    field.zero_also = true;
    return AddNumber(std::move(field), member);
  }
  OptionFields& AddDouble(const std::string& name, double Options::*member, const std::string& doc,
                          double min = std::numeric_limits<double>::lowest(),
                          double max = std::numeric_limits<double>::max()) {
    return AddNumber(NumberField(name, doc, OptionField::Type::kDouble, min, max), member);
  }
  OptionFields& AddBool(const std::string& name, bool Options::*member, const std::string& doc) {
    Add(PlainField(name, doc, OptionField::Type::kBool),
        [member](const OptionField& field, Options* object, OptionFieldVisitor* visitor) {
          visitor->Bool(field, &(object->*member));
        });
    return *this;
  }
  OptionFields& AddString(const std::string& name, std::string Options::*member,
                          const std::string& doc) {
    Add(PlainField(name, doc, OptionField::Type::kString),
        [member](const OptionField& field, Options* object, OptionFieldVisitor* visitor) {
          visitor->String(field, &(object->*member));
        });
    return *this;
  }
  // A list of numbers, each in [min, max].
  OptionFields& AddDoubleList(const std::string& name, std::vector<double> Options::*member,
                              const std::string& doc,
                              double min = std::numeric_limits<double>::lowest(),
                              double max = std::numeric_limits<double>::max()) {
    Entry& entry =
        Add(NumberField(name, doc, OptionField::Type::kDoubleList, min, max),
            [member](const OptionField& field, Options* object, OptionFieldVisitor* visitor) {
              visitor->DoubleList(field, &(object->*member));
            });
    entry.check = [member](const OptionField& field, const Options& object,
                           const std::string& field_name) {
      const std::vector<double>& values = object.*member;
      internal::CheckDeclaredNumbers(values.data(), static_cast<int>(values.size()), field,
                                     field_name);
    };
    return *this;
  }
  // An enum with a table of names (enum_names.h): its choices.
  template <typename Enum>
  OptionFields& AddEnum(const std::string& name, Enum Options::*member, const std::string& doc) {
    OptionField field = PlainField(name, doc, OptionField::Type::kChoice);
    field.choices = EnumNameList<Enum>();
    Entry& entry = Add(std::move(field), [member](const OptionField& field, Options* object,
                                                  OptionFieldVisitor* visitor) {
      Enum* value = &(object->*member);
      visitor->Choice(
          field, [value](const std::string& text) { StringToEnum(text, value); },
          [value] { return EnumToString(*value); });
    });
    entry.check = [member](const OptionField&, const Options& object,
                           const std::string& field_name) {
      internal::CheckDeclaredChoice(IsKnownEnum(object.*member), static_cast<int>(object.*member),
                                    field_name);
    };
    return *this;
  }
  // A field whose key the config makes itself (OptionFieldVisitor::Custom); `min` and `max`
  // bound its numbers, if any.
  OptionFields& AddCustom(const std::string& name, const std::string& doc,
                          double min = std::numeric_limits<double>::lowest(),
                          double max = std::numeric_limits<double>::max()) {
    Add(NumberField(name, doc, OptionField::Type::kCustom, min, max),
        [](const OptionField& field, Options*, OptionFieldVisitor* visitor) {
          visitor->Custom(field);
        });
    return *this;
  }
  // A nested options struct, declared by `fields`, as the section `name`.
  template <typename Section>
  OptionFields& AddSection(const std::string& name, Section Options::*member,
                           const OptionFields<Section>& fields) {
    Add(PlainField(name, "", OptionField::Type::kSection),
        [member, &fields](const OptionField& field, Options* object, OptionFieldVisitor* visitor) {
          visitor->BeginSection(field);
          fields.Visit(&(object->*member), visitor);
          visitor->EndSection();
        });
    return *this;
  }

  // A nested options struct, declared by `fields`, whose fields are keys of this struct's own
  // section, as if declared here: a group kept in a struct of its own (the terms' options, which
  // their registry declares). Like a section, its Check() is its own.
  template <typename Group>
  OptionFields& AddGroup(Group Options::*member, const OptionFields<Group>& fields) {
    Add(PlainField("", "", OptionField::Type::kGroup),
        [member, &fields](const OptionField&, Options* object, OptionFieldVisitor* visitor) {
          fields.Visit(&(object->*member), visitor);
        });
    return *this;
  }

  // Hands every field of `*object`, in declaration order, to `visitor`.
  void Visit(Options* object, OptionFieldVisitor* visitor) const {
    for (const Entry& entry : entries_) entry.visit(entry.field, object, visitor);
  }

  // Throws Error(prefix + name, ...) for the first field of `object` outside its declared range
  // or choices; `prefix` names the struct ("EnergyOptions::"). Sections are left to their own
  // Check().
  void CheckValues(const Options& object, const std::string& prefix) const {
    for (const Entry& entry : entries_) {
      if (entry.check) entry.check(entry.field, object, prefix + entry.field.name);
    }
  }

  // The declaration of the field `name`: for a rule across fields that shares a bound with it,
  // or a custom key.
  const OptionField& Field(const std::string& name) const {
    for (const Entry& entry : entries_) {
      if (entry.field.name == name) return entry.field;
    }
    throw std::invalid_argument("no declared option field '" + name + "'");
  }

  std::vector<OptionField> Declared() const {
    std::vector<OptionField> fields;
    for (const Entry& entry : entries_) fields.push_back(entry.field);
    return fields;
  }

 private:
  using VisitFunction = std::function<void(const OptionField&, Options*, OptionFieldVisitor*)>;
  using CheckFunction =
      std::function<void(const OptionField&, const Options&, const std::string& field_name)>;
  struct Entry {
    OptionField field;
    VisitFunction visit;
    CheckFunction check;  // Empty when nothing is declared to check.
  };

  static OptionField PlainField(const std::string& name, const std::string& doc,
                                OptionField::Type type) {
    OptionField field;
    field.name = name;
    field.doc = doc;
    field.type = type;
    return field;
  }
  template <typename T>
  static OptionField NumberField(const std::string& name, const std::string& doc,
                                 OptionField::Type type, T min, T max) {
    OptionField field = PlainField(name, doc, type);
    field.min = min == std::numeric_limits<T>::lowest() ? std::numeric_limits<double>::lowest()
                                                        : static_cast<double>(min);
    field.max = max == std::numeric_limits<T>::max() ? std::numeric_limits<double>::max()
                                                     : static_cast<double>(max);
    return field;
  }

  Entry& Add(OptionField field, VisitFunction visit) {
    entries_.push_back({std::move(field), std::move(visit), nullptr});
    return entries_.back();
  }
  template <typename T>
  OptionFields& AddNumber(OptionField field, T Options::*member) {
    Entry& entry = Add(std::move(field), [member](const OptionField& field, Options* object,
                                                  OptionFieldVisitor* visitor) {
      if constexpr (std::is_same_v<T, int>) {
        visitor->Int(field, &(object->*member));
      } else {
        visitor->Double(field, &(object->*member));
      }
    });
    entry.check = [member](const OptionField& field, const Options& object,
                           const std::string& field_name) {
      internal::CheckDeclaredNumber(static_cast<double>(object.*member), field, field_name);
    };
    return *this;
  }

  std::vector<Entry> entries_;
};

}  // namespace finecap

#endif  // FINECAP_UTIL_OPTION_FIELDS_H_
