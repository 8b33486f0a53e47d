// Many float rays through the voxel world at once: each lane of a SIMD register walks one
// ray, and a lane whose ray ends takes the next ray of the stream (rays are started a vector
// at a time). Every lane runs one kind of step, leaving the empty cube around its cell: the
// voxel, a 4^3 brick or a slot (shaders/shared/rdm_walk.h's walkLeave), an 8^3 octant of a
// block, or a 2 x 2 x 2 group of slots; an axis crossing a voxel plane (a slot plane, for
// slots and groups) exactly at the exit time joins the mask, as the smaller steps through the
// cube would have it. Each ray's hit is referenceWalk's, bit for bit, whatever the vector
// width (tests/trace/voxel_stream_test.cpp). The width is the widest the CPU has (Highway's
// dynamic dispatch, SSSE3 to AVX-512); docs/performance.md has the rates beside traceVoxels
// and Embree.
#pragma once

#include <span>

#include "rdm/trace/traversal.h"

namespace rdm {

// hits[i] and t_hits[i] are what traceVoxels(world, rays[i], t_hits[i]) gives (hit.steps
// counts this walk's steps; t_hits[i] is left alone on a miss). Irregular rays
// (FloatRay::regular) take referenceWalk.
void traceVoxelStream(const VoxelWorld& world, std::span<const FloatRay> rays,
                      std::span<TraceHit> hits, std::span<float> t_hits);

// The vector width traceVoxelStream runs at on this CPU, in floats, and the target's name.
int voxelStreamLanes();
const char* voxelStreamTarget();

}  // namespace rdm
