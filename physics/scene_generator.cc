#include "physics/scene_generator.h"

#include "physics/seeds.h"

namespace tubepick::physics {

DropResult GenerateScene(const SceneParams& params, std::uint64_t seed) {
  const std::vector<TubeGeometry> tubes =
      GenerateRandomTubes(params.tube_count, params.tubes, DeriveSeed(seed, 1));
  return DropTubes(tubes, params.bin, params.drop, DeriveSeed(seed, 2));
}

}  // namespace tubepick::physics
