#pragma once
// JSON of any message of idl/crane_msgs.idl, for crane_topic echo and record (and the transport
// tests' field-by-field comparisons). No field list here: names, order and nesting come from the
// IDL through the generated crane::protocol::visit_fields (idl/tools/gen_protocol.py).
#include <array>
#include <cstddef>
#include <nlohmann/json.hpp>
#include <string_view>
#include <type_traits>

#include "crane/protocol/dds.hpp"

namespace crane::launch {

namespace detail {

struct IgnoreField {
  template <class Value>
  void operator()(std::string_view /*name*/, const Value& /*value*/) const noexcept {}
};

template <class T>
concept ProtocolStruct = requires(const T& m) { protocol::visit_fields(m, IgnoreField{}); };

template <class T>
struct IsStdArray : std::false_type {};
template <class T, std::size_t N>
struct IsStdArray<std::array<T, N>> : std::true_type {};

}  // namespace detail

/// One field's value: a nested struct as an object, an array as an array, integers as numbers
/// (uint8 too), booleans as true/false, floating point as numbers (NaN and Inf as null, as
/// nlohmann::json writes them).
template <class T>
[[nodiscard]] nlohmann::json field_json(const T& value) {
  if constexpr (detail::ProtocolStruct<T>) {
    nlohmann::json object = nlohmann::json::object();
    protocol::visit_fields(value, [&object](std::string_view name, const auto& field) {
      object[std::string(name)] = field_json(field);
    });
    return object;
  } else if constexpr (detail::IsStdArray<T>::value) {
    nlohmann::json array = nlohmann::json::array();
    for (const auto& element : value) array.push_back(field_json(element));
    return array;
  } else {
    static_assert(std::is_arithmetic_v<T>, "a field of the IDL is a struct, an array or a number");
    return nlohmann::json(value);
  }
}

/// {"field": value, ...} of a fastddsgen message (any type of the IDL): one key per field of
/// the IDL, nested structs (header, its stamps) as objects, arrays as arrays. Allocates.
template <class DdsMessage>
  requires requires { typename protocol::PlainOf<DdsMessage>::type; }
[[nodiscard]] nlohmann::json message_json(const DdsMessage& m) {
  typename protocol::PlainOf<DdsMessage>::type plain;
  protocol::from_dds(m, plain);
  return field_json(plain);
}

}  // namespace crane::launch
