// The state of a model as plain records (numbers, strings, lists, tuples), every field exactly:
// what pickling sends to another process (spacar.sweep, dask), so that the model received is the
// same model, state included. The records are generated from the field tables of model.hpp; the
// bindings only convert them to Python objects and back.
#pragma once

#include <array>
#include <cstddef>
#include <string>
#include <tuple>
#include <type_traits>
#include <utility>
#include <vector>

#include "spacar/model/catalogue.hpp"
#include "spacar/model/model.hpp"

namespace spacar {

// Raised with every change of the record layout (the field tables or ModelState).
constexpr int kModelStateVersion = 1;

// InputError "invalid pickled spacar model: <why>".
[[noreturn]] void bad_model_state(const std::string& why);

template <class E>
constexpr E enum_last();
template <>
constexpr NodeKind enum_last<NodeKind>() { return NodeKind::Lambda; }
template <>
constexpr CoordClass enum_last<CoordClass>() { return CoordClass::Dynamic; }
template <>
constexpr DefClass enum_last<DefClass>() { return DefClass::Kinematic; }

namespace detail {
template <class T>
struct is_enum_vector : std::false_type {};
template <class E>
struct is_enum_vector<std::vector<E>> : std::is_enum<E> {};

template <class E>
E checked_enum(int v, const char* field) {
  if (v < 0 || v > static_cast<int>(enum_last<E>())) bad_model_state(std::string(field) + " out of range");
  return static_cast<E>(v);
}
}  // namespace detail

template <class Codec>
struct FieldCodec;

template <>
struct FieldCodec<AsStored> {
  template <class T>
  static auto encode(const T& v) {
    if constexpr (std::is_enum_v<T>) {
      return static_cast<int>(v);
    } else if constexpr (detail::is_enum_vector<T>::value) {
      std::vector<int> out;
      for (auto c : v) out.push_back(static_cast<int>(c));
      return out;
    } else {
      return v;
    }
  }
  template <class R, class T>
  static void decode(const R& r, T& v, const char* field) {
    if constexpr (std::is_enum_v<T>) {
      v = detail::checked_enum<T>(r, field);
    } else if constexpr (detail::is_enum_vector<T>::value) {
      v.clear();
      for (int c : r) v.push_back(detail::checked_enum<typename T::value_type>(c, field));
    } else {
      v = r;
    }
  }
};

template <>
struct FieldCodec<ElementTypeByName> {
  static std::string encode(int type) { return element_catalogue()[type].name; }
  static void decode(const std::string& name, int& type, const char*) {
    type = find_element_type(name);
    if (type < 0) bad_model_state("element type " + name);
  }
};

// The record of one struct: the tuple of its fields in the order of its field table.
template <class S, class... F>
auto encode_record(const S& s, const std::tuple<F...>& fields) {
  return std::apply([&s](const auto&... f) { return std::make_tuple(encode_field(s, f)...); }, fields);
}

template <class S, class T, class C>
auto encode_field(const S& s, const Field<S, T, C>& f) {
  return FieldCodec<C>::encode(s.*(f.member));
}

template <class S, class Fields, class Record>
void decode_record(const Record& r, S& s, const Fields& fields) {
  decode_fields(r, s, fields, std::make_index_sequence<std::tuple_size_v<Fields>>{});
}

template <class S, class Fields, class Record, std::size_t... I>
void decode_fields(const Record& r, S& s, const Fields& fields, std::index_sequence<I...>) {
  (decode_field(std::get<I>(r), s, std::get<I>(fields)), ...);
}

template <class R, class S, class T, class C>
void decode_field(const R& r, S& s, const Field<S, T, C>& f) {
  FieldCodec<C>::decode(r, s.*(f.member), f.name);
}

using NodeRecord = decltype(encode_record(std::declval<const Node&>(), kNodeFields));
using ElementRecord = decltype(encode_record(std::declval<const Element&>(), kElementFields));
using SettingsRecord = decltype(encode_record(std::declval<const Settings&>(), kSettingsFields));

// (version, nodes, elements, settings, time, gravity, gravity given, prepared)
using ModelState = std::tuple<int, std::vector<NodeRecord>, std::vector<ElementRecord>, SettingsRecord, double,
                              std::array<double, 3>, bool, bool>;

ModelState model_state(const Model& m);
// The model of a state, checked (sizes, node kinds of the element slots, references of the
// nonholonomic deformations): InputError if the state is not one that model_state() gives.
Model model_from_state(const ModelState& state);

}  // namespace spacar
