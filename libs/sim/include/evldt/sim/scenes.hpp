#pragma once
// The built-in scenes, by name (see README: each mirrors a recording of the seed paper).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include "evldt/sim/event_simulator.hpp"
#include "evldt/sim/scene.hpp"

namespace evldt {

inline constexpr std::string_view kDefaultScene = "boxes-6dof";

const std::vector<std::string>& scene_names();
/// Throws std::invalid_argument listing the valid names for an unknown one.
Scene make_scene(std::string_view name);
/// The event-camera model a scene is seen through: the default for most, a noisy, flickering or
/// dark sensor for the scenes made for those (noisy-boxes, flicker-lamps, night-boxes).
SimulatorConfig scene_camera_model(std::string_view name);
/// Another recording of the same scene: every oscillation of the camera motion gets a new phase and
/// its amplitude and frequency scaled by 0.8-1.25, drawn from `seed` (the scene itself for seed 0).
/// The name gets "/m<seed>". For held-out runs: parameters tuned on a scene are scored on its
/// variants too.
Scene vary_camera_motion(Scene scene, std::uint64_t seed);
/// The scene with a bar in front of everything that sweeps across the image and back (one crossing
/// a second, a sine in time), as a pole or an arm passing the camera: it hides each edge it passes
/// for about `hidden_us` at the image's middle (its width is made so; longer towards the sides, where
/// it is slower). Its own vertical edges are ground truth like any other. Throws
/// std::invalid_argument where no bar hides that long at that speed (hidden_us >= 1 / pi s). The
/// name gets "/o<ms>".
Scene with_occluder(Scene scene, Timestamp hidden_us);

}  // namespace evldt
