// Copyright the msfusion authors. SPDX-License-Identifier: BSD-3-Clause
#pragma once
#include <type_traits>
#include <utility>

namespace msf::detail {

/// Compile-time tests for the optional fields of a point type, so that one template serves
/// PCL's types and the project's registered ones (a field is written only where it exists).
template <typename T, typename = void>
struct has_rgb : std::false_type {};
template <typename T>
struct has_rgb<T, std::void_t<decltype(std::declval<T&>().r), decltype(std::declval<T&>().rgb)>> : std::true_type {};
template <typename T>
inline constexpr bool has_rgb_v = has_rgb<T>::value;

template <typename T, typename = void>
struct has_confidence : std::false_type {};
template <typename T>
struct has_confidence<T, std::void_t<decltype(std::declval<T&>().confidence)>> : std::true_type {};
template <typename T>
inline constexpr bool has_confidence_v = has_confidence<T>::value;

template <typename T, typename = void>
struct has_distance : std::false_type {};
template <typename T>
struct has_distance<T, std::void_t<decltype(std::declval<T&>().distance)>> : std::true_type {};
template <typename T>
inline constexpr bool has_distance_v = has_distance<T>::value;

template <typename T, typename = void>
struct has_weight : std::false_type {};
template <typename T>
struct has_weight<T, std::void_t<decltype(std::declval<T&>().weight)>> : std::true_type {};
template <typename T>
inline constexpr bool has_weight_v = has_weight<T>::value;

template <typename T, typename = void>
struct has_free_space_weight : std::false_type {};
template <typename T>
struct has_free_space_weight<T, std::void_t<decltype(std::declval<T&>().free_space_weight)>> : std::true_type {};
template <typename T>
inline constexpr bool has_free_space_weight_v = has_free_space_weight<T>::value;

template <typename T, typename = void>
struct has_sky_depth : std::false_type {};
template <typename T>
struct has_sky_depth<T, std::void_t<decltype(std::declval<T&>().sky_depth)>> : std::true_type {};
template <typename T>
inline constexpr bool has_sky_depth_v = has_sky_depth<T>::value;

template <typename T, typename = void>
struct has_intensity : std::false_type {};
template <typename T>
struct has_intensity<T, std::void_t<decltype(std::declval<T&>().intensity)>> : std::true_type {};
template <typename T>
inline constexpr bool has_intensity_v = has_intensity<T>::value;

} // namespace msf::detail
