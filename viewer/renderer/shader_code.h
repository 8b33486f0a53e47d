// SPIR-V of viewer/shaders/*, compiled at build time by glslangValidator and embedded.
#pragma once

#include <cstddef>
#include <cstdint>

namespace rdm::viewer {

enum class ShaderId {
  kBlockVert,
  kBlockFrag,
  kShadowVert,
  kFullscreenVert,
  kSkyFrag,
  kAccumulateFrag,
  kTonemapFrag
};

struct ShaderCode {
  const uint32_t* words;
  size_t bytes;
};

ShaderCode shaderCode(ShaderId id);

}  // namespace rdm::viewer
