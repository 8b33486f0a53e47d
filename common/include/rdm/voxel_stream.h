// Many float rays through the voxel world at once: each lane of a SIMD register walks one
// ray, and a lane whose ray ends takes the next ray of the stream. Every lane runs the step
// of shaders/shared/rdm_walk.h (walkLeave: leave the empty slot, the empty 4^3 brick or the
// voxel holding the cell), so each ray's hit is referenceWalk's, bit for bit, whatever the
// vector width (tests/voxel_stream_test.cpp). The width is the widest the CPU has (Highway's
// dynamic dispatch: SSE2 to AVX-512); docs/performance.md has the rates beside traceVoxels
// and Embree.
#pragma once

#include <span>

#include "rdm/traversal.h"

namespace rdm {

// hits[i] and t_hits[i] are what traceVoxels(world, rays[i], t_hits[i]) gives (hit.steps
// counts the walk's steps). Irregular rays (FloatRay::regular) take referenceWalk.
void traceVoxelStream(const VoxelWorld& world, std::span<const FloatRay> rays,
                      std::span<TraceHit> hits, std::span<float> t_hits);

// The vector width traceVoxelStream runs at on this CPU, in floats, and the target's name.
int voxelStreamLanes();
const char* voxelStreamTarget();

}  // namespace rdm
