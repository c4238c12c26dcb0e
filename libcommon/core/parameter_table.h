// A stage's parameters, declared once (docs/conventions.md §7 "Stages with one shape"): one
// table per options struct gives each parameter's name, field, default (the struct's), help,
// check and help group. The provenance parameters (ParameterTable::toJson), the command line
// (tools/common/parameter_cli.h binds every entry to CLI11), --print-defaults (the bound
// defaults), library-side validation (ParameterTable::validate) and the quality presets
// (ParameterTable::apply) all read the one table, so a parameter's name is written once.
// No command line here: libcommon knows no CLI11.
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "libcommon/core/error.h"
#include "libcommon/core/parameter_check.h"

namespace rad {

// Where --help lists a parameter (docs/design.md §1 "Parameters").
enum class ParameterGroup {
  kCommon,    // what a user sets: frames, size, outputs, presets
  kQuality,   // what the presets set: accuracy against time
  kAdvanced,  // memory bounds, algorithm choices, tuning
  kBaseline,  // exists only to compare against a baseline (--no-coherence, --no-clustering)
};
const char* parameterGroupTitle(ParameterGroup group);

// An enum's names, written once: parse, print and the command line's check all come from it.
template <class E>
class EnumNames {
 public:
  EnumNames(std::initializer_list<std::pair<E, const char*>> entries) : entries_(entries) {}
  // The names from an existing namer, e.g. EnumNames::of({kA, kB}, nameOfE).
  static EnumNames of(std::initializer_list<E> values, const char* (*namer)(E)) {
    EnumNames names({});
    for (E v : values) names.entries_.emplace_back(v, namer(v));
    return names;
  }
  const char* name(E value) const {
    for (const auto& [v, n] : entries_)
      if (v == value) return n;
    throw Error(ExitCode::kInternal, "", "enum value without a name");
  }
  std::optional<E> find(const std::string& text) const {
    for (const auto& [v, n] : entries_)
      if (text == n) return v;
    return std::nullopt;
  }
  // Usage Error `--flag text: expected one of a, b, c` for a name not in the table.
  E parse(const std::string& text, const std::string& flag) const {
    if (std::optional<E> v = find(text)) return *v;
    throw Error(ExitCode::kUsage, "", flag + " " + text + ": expected one of " + list(", "));
  }
  std::vector<std::string> names() const {
    std::vector<std::string> out;
    for (const auto& entry : entries_) out.push_back(entry.second);
    return out;
  }
  std::string list(const std::string& sep) const {
    std::string out;
    for (const auto& entry : entries_) out += (out.empty() ? "" : sep) + entry.second;
    return out;
  }

 private:
  std::vector<std::pair<E, const char*>> entries_;
};

// One parameter of options struct O, type-erased: what the table's users need.
template <class O>
struct Parameter {
  std::string name;  // the long option without "--", and the provenance key
  std::string help;
  ParameterGroup group = ParameterGroup::kAdvanced;
  ParameterCheck check;
  enum class Kind { kValue, kFlag } kind = Kind::kValue;
  bool inProvenance = true;  // false: the run's plumbing (a report file), not an output's content
  std::string typeName;      // INT, FLOAT, TEXT, or the enum's names
  std::vector<std::string> choices;                 // an enum's names; else empty
  std::function<nlohmann::json(const O&)> value;    // as the provenance records it
  std::function<std::string(const O&)> text;        // as the command line writes it; "" unset
  std::function<void(O&, const std::string&)> set;  // from command-line text (checked)
};

namespace detail {
template <class T>
struct IsOptional : std::false_type {};
template <class T>
struct IsOptional<std::optional<T>> : std::true_type {};

// The command line's text for a value: numbers as JSON writes them (the shortest text that
// reads back to the same double), so --print-defaults and the provenance agree.
template <class T>
std::string textOf(const T& v) {
  if constexpr (std::is_same_v<T, std::string>) {
    return v;
  } else if constexpr (IsOptional<T>::value) {
    return v ? textOf(*v) : std::string();
  } else {
    return nlohmann::json(v).dump();
  }
}

template <class T>
T fromText(const std::string& s, const std::string& name) {
  if constexpr (std::is_same_v<T, std::string>) {
    return s;
  } else if constexpr (IsOptional<T>::value) {
    return fromText<typename T::value_type>(s, name);
  } else {
    const nlohmann::json j = nlohmann::json::parse(s, nullptr, false);
    if (!j.is_number())
      throw Error(ExitCode::kUsage, "", "--" + name + " " + s + ": expected a number");
    if constexpr (std::is_floating_point_v<T>) return j.get<T>();
    if (!j.is_number_integer())
      throw Error(ExitCode::kUsage, "", "--" + name + " " + s + ": expected an integer");
    return j.get<T>();
  }
}

template <class T>
const char* typeNameOf() {
  if constexpr (IsOptional<T>::value) return typeNameOf<typename T::value_type>();
  if constexpr (std::is_floating_point_v<T>) return "FLOAT";
  if constexpr (std::is_integral_v<T>) return "INT";
  return "TEXT";
}
}  // namespace detail

// The parameters of options struct O, in --help's order. Fields are given as a member pointer
// (&O::fps) or a callable returning a reference into O (for nested structs).
template <class O>
class ParameterTable {
 public:
  // A value option: number, string or std::optional of one. JSON: the value (null if unset).
  template <class F>
  ParameterTable& add(const std::string& name, F field, const std::string& help,
                      ParameterCheck check = {}, ParameterGroup group = ParameterGroup::kAdvanced) {
    using T = std::remove_cv_t<std::remove_reference_t<std::invoke_result_t<F, O&>>>;
    Parameter<O> p = base(name, help, group);
    p.check = check;
    p.typeName = detail::typeNameOf<T>();
    p.value = [field](const O& o) -> nlohmann::json {
      const T& v = std::invoke(field, const_cast<O&>(o));
      if constexpr (detail::IsOptional<T>::value)
        return v ? nlohmann::json(*v) : nlohmann::json();
      else
        return nlohmann::json(v);
    };
    p.text = [field](const O& o) { return detail::textOf(std::invoke(field, const_cast<O&>(o))); };
    p.set = [field, name](O& o, const std::string& s) {
      std::invoke(field, o) = detail::fromText<T>(s, name);
    };
    return push(std::move(p));
  }

  // An enum option; JSON and command line: its name in `names`. The field may be a
  // std::optional<E>: unset is JSON null and no command-line text (resolved at run).
  template <class F, class E>
  ParameterTable& addEnum(const std::string& name, F field, const EnumNames<E>& names,
                          const std::string& help,
                          ParameterGroup group = ParameterGroup::kAdvanced) {
    using T = std::remove_cv_t<std::remove_reference_t<std::invoke_result_t<F, O&>>>;
    Parameter<O> p = base(name, help, group);
    p.choices = names.names();
    p.typeName = "TEXT";
    p.value = [field, names](const O& o) -> nlohmann::json {
      const T& v = std::invoke(field, const_cast<O&>(o));
      if constexpr (detail::IsOptional<T>::value)
        return v ? nlohmann::json(names.name(*v)) : nlohmann::json();
      else
        return names.name(v);
    };
    p.text = [field, names](const O& o) {
      const T& v = std::invoke(field, const_cast<O&>(o));
      if constexpr (detail::IsOptional<T>::value)
        return v ? std::string(names.name(*v)) : std::string();
      else
        return std::string(names.name(v));
    };
    p.set = [field, names, name](O& o, const std::string& s) {
      std::invoke(field, o) = names.parse(s, "--" + name);
    };
    return push(std::move(p));
  }

  // A flag that sets bool `field` to `when` (true for --half, false for --no-closure). JSON:
  // whether the flag is in effect, so a --no-X flag records "no-X": true when X is off.
  template <class F>
  ParameterTable& addFlag(const std::string& name, F field, bool when, const std::string& help,
                          ParameterGroup group = ParameterGroup::kAdvanced) {
    Parameter<O> p = base(name, help, group);
    p.kind = Parameter<O>::Kind::kFlag;
    p.value = [field, when](const O& o) -> nlohmann::json {
      return std::invoke(field, const_cast<O&>(o)) == when;
    };
    p.text = [field, when](const O& o) {
      return std::string(std::invoke(field, const_cast<O&>(o)) == when ? "true" : "false");
    };
    p.set = [field, when](O& o, const std::string& s) {
      std::invoke(field, o) = (s == "false") ? !when : when;
    };
    return push(std::move(p));
  }

  // The last entry added is the run's plumbing: bound to the command line, not in toJson.
  ParameterTable& notInProvenance() {
    entries_.back().inProvenance = false;
    return *this;
  }

  const std::vector<Parameter<O>>& entries() const { return entries_; }
  const Parameter<O>* find(const std::string& name) const {
    for (const Parameter<O>& p : entries_)
      if (p.name == name) return &p;
    return nullptr;
  }

  // The provenance parameters: every entry in provenance under its name.
  nlohmann::json toJson(const O& o) const {
    nlohmann::json out = nlohmann::json::object();
    for (const Parameter<O>& p : entries_)
      if (p.inProvenance) out[p.name] = p.value(o);
    return out;
  }

  // Sets `values` (name -> command-line text), as a preset does. Internal Error on a name the
  // table does not have (a preset naming a parameter that is gone).
  void apply(O& o, const std::vector<std::pair<std::string, std::string>>& values) const {
    for (const auto& [name, text] : values) {
      const Parameter<O>* p = find(name);
      if (p == nullptr) throw Error(ExitCode::kInternal, "", "no parameter --" + name);
      p->set(o, text);
    }
  }

  // Usage Error naming the first value outside its check: `--eps -1: expected a finite number
  // >= 0`. The command line checks the same before it sets a value; this is for library callers.
  void validate(const O& o) const {
    for (const Parameter<O>& p : entries_) {
      if (p.kind != Parameter<O>::Kind::kValue || !p.choices.empty()) continue;
      const std::string text = p.text(o);
      if (text.empty()) continue;  // unset optional or empty string: resolved at run
      const std::string problem = p.check.problem(text, p.typeName == std::string("INT"));
      if (!problem.empty()) throw Error(ExitCode::kUsage, "", "--" + p.name + " " + problem);
    }
  }

 private:
  Parameter<O> base(const std::string& name, const std::string& help, ParameterGroup group) {
    Parameter<O> p;
    p.name = name;
    p.help = help;
    p.group = group;
    return p;
  }
  ParameterTable& push(Parameter<O> p) {
    for (const Parameter<O>& q : entries_)
      if (q.name == p.name) throw Error(ExitCode::kInternal, "", "--" + p.name + " declared twice");
    entries_.push_back(std::move(p));
    return *this;
  }
  std::vector<Parameter<O>> entries_;
};

// A quality preset: a name and the parameters it sets, as command-line text. "default" sets
// nothing. Explicit flags override it (tools/common/parameter_cli.h).
struct Preset {
  std::string name;
  std::vector<std::pair<std::string, std::string>> values;
};
// The preset names every stage tool takes, in order.
inline const std::vector<std::string>& presetNames() {
  static const std::vector<std::string> names{"draft", "default", "final"};
  return names;
}
// The values `name` sets from a stage's `presets` (a preset the stage does not list sets
// nothing there: draft touches only rad-global). Usage Error on an unknown name.
const Preset& findPreset(const std::vector<Preset>& presets, const std::string& name);

}  // namespace rad
