// PPF settings: Drost et al. 2010 ("Model globally, match locally") on PCL's
// pair feature, with the improvements of Vidal, Lin and Marti 2018 (and
// Hinterstoisser et al. 2016): model and scene sampled by distance steps
// with normal clustering, neighbouring bins looked up, one vote per
// quantized scene pair, pose clusters averaged. Setting model_points 300,
// model_sampling_steps 0, normal_cluster_deg 0 and vote_once false gives the
// plain method (PCL's usage).
//
// Defaults, as measured (the LS5 on occluded table scenes with distractors,
// 30 images, ICP: configs/experiments/ppf.yaml, results/ppf/README.md):
// correct (a correct hypothesis among the ranked ones), median time per
// image on one core:
//   plain (300 points, every vote)            13 (16)  0.12 s
//   default (2 steps, normal clusters, once)  15 (23)  0.16 s
//   default + neighbour_margin 0.25           12 (25)  0.59 s
//   Vidal's 1 step + neighbour_margin 0.25    16 (27)  4.1 s
// So the default samples the model at 2 steps and looks up its own bin.
#pragma once

#include "core/settings_fields.h"

namespace pb {

struct PpfSettings {
  int model_points = 1000;                // at most this many model points (the pair table grows
                                          // with their square): a finer sampling is coarsened until
                                          // this many remain; with model_sampling_steps 0 the model
                                          // is downsampled to about this many
  double model_sampling_steps = 2.0;      // the model is voxel-sampled at this many distance steps
                                          // (distance_step_fraction x diameter); Drost et al. and
                                          // Vidal et al. use 1; 0 = to about model_points points
                                          // (PCL's usage)
  double normal_cluster_deg = 30.0;       // model and scene sampling: a voxel keeps one point per
                                          // group of normals within this angle, so both sides of an
                                          // edge survive (Vidal et al.); 0 = one point per voxel
  double angle_step_deg = 12.0;           // discretization of the pair feature angles
  double distance_step_fraction = 0.05;   // distance step as a fraction of the diameter
  double neighbour_margin = 0;            // a feature value (or alpha) within this fraction of a bin
                                          // from a bin edge is also looked up (voted) in the
                                          // neighbouring bin across that edge, so noise that moves a
                                          // value over an edge still matches (Vidal et al.: 0.25
                                          // here); 0 = its own bin only
  bool vote_once = true;                  // a scene reference votes at most once per model bin and
                                          // alpha_s bin (Hinterstoisser et al.'s flags): flat
                                          // regions with many equal pairs do not swamp the votes
  double scene_reference_fraction = 0.2;  // fraction of scene points used as references
  double scene_sampling_steps = 1.0;      // the scene is voxel-downsampled (with normal clustering)
                                          // to this many distance steps (distance_step_fraction x
                                          // diameter) before references and pairs are drawn (Drost
                                          // et al.); 0 = the preprocessed scene as is
  double scene_partner_steps = 2.0;       // a reference point's partners (the second points of its
                                          // pairs) from the scene voxel-sampled (with normal
                                          // clustering) at this many distance steps, the model's
                                          // sampling; the references still from
                                          // scene_sampling_steps. On the real LM-O frame 2 against
                                          // 0: 31 against 35 of 80 found (McNemar p = 0.34), the
                                          // median time per object 477 -> 234 ms
                                          // (results/ppf/README.md); 0 = the references' sampling
                                          // (Drost et al.)
  double position_cluster_mm = 30.0;      // pose clustering: translation threshold
  double rotation_cluster_deg = 30.0;     // pose clustering: rotation threshold
  int max_hypotheses = 20;                // clustered poses passed on (to refinement and
                                          // verification). 20 against 5 on the real frames
                                          // (results/real_recognition): a correct one among them
                                          // on YCB-Video 40 -> 97 of 223, found 18 -> 40; on the
                                          // LM-O frame 4 -> 5 of 8, found 4 -> 4; median time per
                                          // object 0.05 -> 0.11 s (YCB-Video), 0.37 -> 0.45 s (LM-O)

  template <class S, class F>
  static void fields(S& s, F& f) {
    // at most 5000: the model's pair features grow with its square
    f("model_points", s.model_points, fields::at_least(10, 5000));
    f("model_sampling_steps", s.model_sampling_steps, fields::nonnegative());
    f("normal_cluster_deg", s.normal_cluster_deg, fields::in_range(0, 180));
    f("angle_step_deg", s.angle_step_deg, fields::positive(90));
    f("distance_step_fraction", s.distance_step_fraction, fields::positive(1));
    f("neighbour_margin", s.neighbour_margin, fields::in_range(0, 0.5));
    f("vote_once", s.vote_once);
    f("scene_reference_fraction", s.scene_reference_fraction, fields::positive(1));
    f("scene_sampling_steps", s.scene_sampling_steps, fields::nonnegative());
    f("scene_partner_steps", s.scene_partner_steps, fields::nonnegative());
    f("position_cluster_mm", s.position_cluster_mm, fields::length(fields::positive()));
    f("rotation_cluster_deg", s.rotation_cluster_deg, fields::positive());
    f("max_hypotheses", s.max_hypotheses, fields::at_least(1));
  }
};

}  // namespace pb
