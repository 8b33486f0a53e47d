// The two ways rdm-viewer runs: offscreen (timed frames, images to files) and in a window.
// Both return the process exit status and print errors themselves.
#pragma once

#include "options.h"
#include "rdm/scene/scene.h"
#include "renderer.h"

namespace rdm::viewer {

// The renderer's options for an image of width x height (shadow map 2048, the atlas at half
// unless --float-atlas, a bc6h atlas as --bc6h-texture says).
inline RendererOptions rendererOptions(const ViewerOptions& o, int width, int height) {
  RendererOptions r;
  r.width = width, r.height = height, r.shadow_map_size = 2048;
  r.atlas_precision = o.float_atlas ? AtlasPrecision::kFloat : AtlasPrecision::kHalf;
  r.bc6h_texture = o.bc6h_texture == "stored"    ? Bc6hTexture::kStored
                   : o.bc6h_texture == "decoded" ? Bc6hTexture::kDecoded
                                                 : Bc6hTexture::kAuto;
  return r;
}

// Loads the scene (and the atlas directory when given) into `renderer`; the index of
// --camera in `scene`. An unknown camera fails naming the scene's cameras.
Expected<size_t> loadViewerContent(Renderer& renderer, const ViewerOptions& options, Scene& scene);

// "RDM on", or "RDM off (no atlas)" / "(--no-rdm or --terms)": what the image shows.
const char* rdmState(const ViewerOptions& options, const Renderer& renderer);

// Writes an RGB8 image as PNG.
Status writeImage8Png(const std::string& path, const Image8& image);

int runOffscreen(const ViewerOptions& options);
int runWindow(const ViewerOptions& options);
// --offscreen and --edit, with --server or in-process (scripted_edit.cpp).
int runScriptedEdit(const ViewerOptions& options);

}  // namespace rdm::viewer
