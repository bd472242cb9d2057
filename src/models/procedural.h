// The project's own models, generated in code (millimetres, up = +z, origin
// at the bounding box centre). Used for the thesis's objects (milk carton,
// LS5-like lidar unit, boletus) and for distractors and occluders.
#pragma once

#include <string>
#include <vector>

#include "core/types.h"

namespace pb {

Mesh make_box(double sx, double sy, double sz);
Mesh make_cylinder(double radius, double height, int segments = 48);
// 1 litre gable-top carton: ~70 x 70 x 195 mm body plus the gable roof and fin.
Mesh make_milk_carton();
// LS5-like lidar unit: a cylindrical sensor head (100 mm across) on a round
// flange (120 mm), 145 mm tall, with a small connector block on the side of
// the head: near-symmetric about its vertical axis. 120 x 120 x 145 mm.
Mesh make_ls5();
// Boletus mushroom: a tapered stem and a domed cap.
Mesh make_boletus();
// A EUR pallet-like slatted pallet (1200 x 800 x 144 mm).
Mesh make_pallet();

// By kind name as used in registry sources ("generated:KIND"). Kinds:
// milk_carton, ls5, boletus, pallet, box (100 mm cube) or "box:SXxSYxSZ"
// (mm, e.g. "box:120x80x60"), cylinder (100 x 100) or
// "cylinder:DIAMETERxHEIGHT" (mm). Throws InputError("", "source", ...) for
// an unknown kind or malformed sizes.
Mesh make_procedural(const std::string& kind);
std::vector<std::string> procedural_kinds();

}  // namespace pb
