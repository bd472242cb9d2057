// SHOT's histogram votes (shot.cpp): each neighbour's vote spread linearly
// over the adjacent cosine bin, shell, elevation half and azimuth sector, as
// PCL's SHOTEstimation does it. One vote at a time, or four at a time with
// AVX2 where the CPU has it: the lanes do the same double and float
// operations in the same order (the file is built without fused
// multiply-adds), then add to the histogram vote by vote, so both give the
// same bits. The angles come from core/trig.h's series (within 4 ulp of
// the true angle, not libm's acos and atan2), the same bits on every
// machine. Internal to the local pipeline; PCL-free.
#pragma once

#include <cstddef>
#include <vector>

#include "core/types.h"

namespace pb::local {

// The SHOT local reference frame: unit axes (rows of R_local_cam).
struct ShotFrame {
  Vec3f x, y, z;
};

// The votes of one neighbourhood, in order: per neighbour its offset from
// the keypoint (p - q, float), the dot product of its normal with the
// frame's z (Eigen's float dot) and its distance (sqrt of the squared
// distance, in double). Neighbours without a finite normal or at distance
// 0 are not pushed (PCL skips them).
struct ShotVotes {
  std::vector<float> ox, oy, oz, nz;
  std::vector<double> dist;
  void clear() {
    ox.clear(), oy.clear(), oz.clear(), nz.clear(), dist.clear();
  }
  void push(const Vec3f& offset, float normal_dot_z, double distance) {
    ox.push_back(offset.x()), oy.push_back(offset.y()), oz.push_back(offset.z());
    nz.push_back(normal_dot_z);
    dist.push_back(distance);
  }
  size_t size() const { return dist.size(); }
};

enum class ShotVotesIsa { best, scalar };

// Adds the votes to h (kShotDim floats and one spare slot after them, which
// takes the additions a vote does not make: +0.0f), radius the support's.
void add_shot_votes(const ShotVotes& v, const ShotFrame& f, double radius, float* h,
                    ShotVotesIsa isa = ShotVotesIsa::best);

}  // namespace pb::local
