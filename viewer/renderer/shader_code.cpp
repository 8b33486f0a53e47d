#include "shader_code.h"

#include "accumulate_frag.h"
#include "block_frag.h"
#include "block_vert.h"
#include "fullscreen_vert.h"
#include "shadow_vert.h"
#include "sky_frag.h"
#include "tonemap_frag.h"

namespace rdm::viewer {

ShaderCode shaderCode(ShaderId id) {
  switch (id) {
    case ShaderId::kBlockVert:
      return {kSpv_block_vert, sizeof(kSpv_block_vert)};
    case ShaderId::kBlockFrag:
      return {kSpv_block_frag, sizeof(kSpv_block_frag)};
    case ShaderId::kShadowVert:
      return {kSpv_shadow_vert, sizeof(kSpv_shadow_vert)};
    case ShaderId::kFullscreenVert:
      return {kSpv_fullscreen_vert, sizeof(kSpv_fullscreen_vert)};
    case ShaderId::kSkyFrag:
      return {kSpv_sky_frag, sizeof(kSpv_sky_frag)};
    case ShaderId::kAccumulateFrag:
      return {kSpv_accumulate_frag, sizeof(kSpv_accumulate_frag)};
    case ShaderId::kTonemapFrag:
      return {kSpv_tonemap_frag, sizeof(kSpv_tonemap_frag)};
  }
  return {nullptr, 0};
}

}  // namespace rdm::viewer
