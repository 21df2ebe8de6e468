// The options of the energy's terms that own a config section below `energy.` (`energy.<term>.`):
// the public half of the registry of terms (src/energy/term_registry.cc, which declares their
// sections, checks them and builds the terms from them). Each struct lives with its term, under
// include/finecap/energy/terms/<term>/ beside src/energy/terms/<term>/, so that a new term with
// options is its folders, a member here and a few lines of the registry.
#ifndef FINECAP_ENERGY_TERM_OPTIONS_H_
#define FINECAP_ENERGY_TERM_OPTIONS_H_

#include <string>
#include <vector>

#include "finecap/energy/terms/temporal/temporal_options.h"
#include "finecap/util/option_fields.h"

namespace finecap {

struct TermOptions {
  TemporalOptions temporal;

  // The terms' sections, each a key group of `energy.` (EnergyOptions::Fields adds them).
  static const OptionFields<TermOptions>& Fields();  // option_fields.h
  void Check() const;
};

// What the config must know of each term's options struct beside its keys.
struct TermOptionSection {
  std::string field_prefix;         // How its Check() names a field: "<Term>Options::".
  std::string key_prefix;           // The config section of its keys: "energy.<term>.".
  std::vector<OptionField> fields;  // Its declaration (OptionFields::Declared).
};
// One entry per struct of TermOptions: so that a Check() failure naming a field is reported at its
// key, and a test can walk every declared range.
const std::vector<TermOptionSection>& TermOptionSections();

}  // namespace finecap

#endif  // FINECAP_ENERGY_TERM_OPTIONS_H_
