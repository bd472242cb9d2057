// The online stages of a descriptor method (describe -> match -> group ->
// initial_pose), run in the data path's order by run_stages, the one place
// that times them into StageTimes. Each family (local/, global/, ppf/)
// writes its stages as plain functions over its own intermediate types;
// its Method::hypothesize is run_stages(*this, ...). PCL-free.
#pragma once

#include <cstdint>
#include <optional>
#include <type_traits>
#include <utility>
#include <vector>

#include "core/stage_times.h"
#include "core/timer.h"
#include "recognition/method.h"

namespace pb {

// What every stage of one hypothesize call reads.
struct SceneInput {
  const PointSet& scene;               // preprocessed scene (plane removed, normals)
  const std::vector<ViewData>& views;  // the trained model's views (view camera frame)
  uint64_t seed;                       // the call's seed
};

namespace stages_detail {

// Whether a family has a group stage (the global family goes from its
// matches straight to initial poses).
template <class F, class = void>
struct has_group : std::false_type {};
template <class F>
struct has_group<F, std::void_t<decltype(&F::group)>> : std::true_type {};

// f()'s result; its wall time added to `seconds`.
template <class Fn>
auto timed(double& seconds, Fn&& f) {
  Timer timer;
  auto result = f();
  seconds += timer.seconds();
  return result;
}

}  // namespace stages_detail

// A family F provides, as const members:
//   std::optional<D> describe(const SceneInput&)          nullopt: nothing to hypothesize
//   M match(const SceneInput&, const D&)
//   G group(const SceneInput&, const D&, M)               optional; without it G is M
//   std::vector<Hypothesis> initial_pose(const SceneInput&, const D&, G)   best first
template <class F>
std::vector<Hypothesis> run_stages(const F& family, const SceneInput& in, StageTimes& times) {
  using stages_detail::timed;
  auto described = timed(times.describe, [&] { return family.describe(in); });
  if (!described) return {};
  auto matched = timed(times.match, [&] { return family.match(in, *described); });
  if constexpr (stages_detail::has_group<F>::value) {
    auto grouped = timed(times.group, [&] { return family.group(in, *described, std::move(matched)); });
    return timed(times.initial_pose, [&] { return family.initial_pose(in, *described, std::move(grouped)); });
  } else {
    return timed(times.initial_pose, [&] { return family.initial_pose(in, *described, std::move(matched)); });
  }
}

}  // namespace pb
