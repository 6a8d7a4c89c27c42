// Named hairstyle presets reproducing Anjyo 1992 Fig. 3 (bob), Fig. 6b (swept back), Fig. 6c
// (ponytail) and Fig. 6d (short cut). Data only: every preset is a HairStyle a scene file could
// spell out in JSON. Angles: azimuth 0 = face, +pi/2 = head's left; zenith 0 = crown.
#include <fmt/format.h>

#include "follicle/core/error.hpp"
#include "follicle/hair/hairdressing_anjyo1992.hpp"

namespace follicle::hair {

namespace {

PoreRegion region(double az0, double az1, double ze0, double ze1, double density, double length,
                  double jitter) {
  PoreRegion r;
  r.azimuth_min = az0;
  r.azimuth_max = az1;
  r.zenith_min = ze0;
  r.zenith_max = ze1;
  r.density = density;
  r.length = length;
  r.length_jitter = jitter;
  return r;
}

PolarRange polar(double az0, double az1, double ze0 = 0.0, double ze1 = kPi) {
  PolarRange p;
  p.azimuth_min = az0;
  p.azimuth_max = az1;
  p.zenith_min = ze0;
  p.zenith_max = ze1;
  return p;
}

ForceField uniform(const Vec3& v, const PolarRange& pores, double above_y = -1e3) {
  ForceField f;
  f.kind = "uniform";
  f.vector = v;
  f.pores = pores;
  f.nodes.axis = Vec3::UnitY();
  f.nodes.min = above_y;
  return f;
}

CutRule cut_below(double y, const PolarRange& pores = {}) {
  CutRule c;
  c.kind = "threshold";
  c.axis = Vec3::UnitY();
  c.threshold = y;
  c.pores = pores;
  return c;
}

// Scalp pores without the face: the front hairline is higher than at the sides and back.
std::vector<PoreRegion> scalp(double density, double length, double jitter) {
  return {region(-kPi, kPi, 0.0, 0.95, density, length, jitter),     // crown and top
          region(0.75, kPi, 0.95, 1.75, density, length, jitter),    // left side and back
          region(-kPi, -0.75, 0.95, 1.75, density, length, jitter),  // right side and back
          region(2.2, -2.2, 1.75, 2.15, density, length, jitter)};   // nape (wraps through pi)
}

HairStyle bob(double ds) {
  HairStyle st;
  st.name = "bob";
  const double dens = 2.5e5 * ds;
  HairPart main;
  main.name = "main";
  main.pores = scalp(dens, 0.24, 0.04);
  main.beam.flexural_rigidity = 5e-9;
  // Parting at the middle (Fig. 5b): above the eyes, the left half is combed to the left and
  // the right half to the right, slightly backwards.
  main.fields.push_back(uniform({9.0, 0.0, -2.0}, polar(0.0, kPi), 0.15));
  main.fields.push_back(uniform({-9.0, 0.0, -2.0}, polar(-kPi, 0.0), 0.15));
  main.cuts.push_back(cut_below(-1.15));                  // the bob line at the jaw
  main.cuts.push_back(cut_below(0.3, polar(-0.9, 0.9)));  // hair falling over the face: bangs
  HairPart bangs;
  bangs.name = "bangs";
  bangs.pores = {region(-0.75, 0.75, 0.45, 0.95, dens, 0.16, 0.03)};
  bangs.beam.flexural_rigidity = 4e-9;
  bangs.fields.push_back(uniform({0.0, 0.0, 10.0}, polar(-kPi, kPi), 0.3));  // comb forward
  bangs.cuts.push_back(cut_below(0.32));  // short bangs above the eyebrows
  st.parts = {main, bangs};
  return st;
}

ForceField radial(double strength, const PolarRange& pores) {
  ForceField f;
  f.kind = "radial";
  f.strength = strength;
  f.pores = pores;
  return f;
}

HairStyle swept_back(double ds) {
  HairStyle st;
  st.name = "swept_back";
  const double dens = 2.5e5 * ds;
  HairPart main;
  main.name = "main";
  main.pores = scalp(dens, 0.2, 0.06);
  main.pores.push_back(region(-0.75, 0.75, 0.45, 0.95, dens, 0.2, 0.06));
  main.beam.flexural_rigidity = 5e-9;
  // Fig. 6b: the force points from the face backwards on the segments above the ears; with
  // gravity the hair leaves the forehead, runs back along the head over the crown (the hull
  // collision keeps it on the head) and falls down the back.
  // In front of the crown the force also lifts (its component along the forehead must point
  // up and back, not down the face).
  main.fields.push_back(uniform({0.0, 0.0, -8.0}, polar(-2.2, 2.2), -0.8));
  ForceField lift = uniform({0.0, 8.0, -10.0}, polar(-2.2, 2.2));
  lift.nodes.axis = Vec3::UnitZ();
  lift.nodes.min = 0.0;
  main.fields.push_back(lift);
  main.beam.load_iterations = 2;
  main.cuts.push_back(cut_below(-1.25));
  // Nothing may fall over the face: cut where q_y - 2 q_z < -1.4 (in front of and below the
  // front hairline, -1.2 there; the back of the head is far above).
  CutRule face;
  face.axis = Vec3(0.0, 1.0, -2.0);
  face.threshold = -1.4;
  main.cuts.push_back(face);
  HairPart tuft;  // the tuft at the side of the temple
  tuft.name = "temple_tuft";
  tuft.pores = {region(1.05, 1.35, 1.2, 1.5, dens * 1.5, 0.09, 0.1),
                region(-1.35, -1.05, 1.2, 1.5, dens * 1.5, 0.09, 0.1)};
  tuft.beam.flexural_rigidity = 2e-9;
  tuft.fields.push_back(uniform({0.0, 0.0, 4.0}, polar(-kPi, kPi)));
  st.parts = {main, tuft};
  return st;
}

HairStyle ponytail(double ds) {
  HairStyle st;
  st.name = "ponytail";
  const double dens = 2.5e5 * ds;
  HairPart tied;
  tied.name = "ponytail";
  tied.pores = scalp(dens, 0.38, 0.08);
  tied.pores.push_back(region(-0.75, 0.75, 0.45, 0.95, dens, 0.38, 0.08));
  tied.beam.flexural_rigidity = 6e-9;
  tied.tie.enabled = true;
  tied.tie.point = Vec3(0.0, 0.25, -1.0);
  tied.tie.radius = 0.01;
  tied.tie.tail_direction = Vec3(0.0, 0.35, -1.0);
  st.parts = {tied};
  return st;
}

HairStyle short_cut(double ds) {
  HairStyle st;
  st.name = "short_cut";
  const double dens = 3.0e5 * ds;
  HairPart main;
  main.name = "main";
  main.pores = scalp(dens, 0.09, 0.05);
  main.pores.push_back(region(-0.75, 0.75, 0.45, 0.95, dens, 0.09, 0.05));
  main.beam.flexural_rigidity = 1.5e-9;
  // Short hair lies on the head: a pull towards the centre (the hull keeps it outside), combed
  // back and down on the top and sides.
  main.fields.push_back(radial(-30.0, polar(-kPi, kPi)));
  main.fields.push_back(uniform({0.0, -3.0, -6.0}, polar(-kPi, kPi)));
  // Fig. 6d: how much is cut depends on the pore height: short at the nape and above the ears,
  // longer on top.
  CutRule c;
  c.kind = "height_length";
  c.height_low = -0.2;
  c.height_high = 0.85;
  c.length_low = 0.012;
  c.length_high = 0.07;
  main.cuts.push_back(c);
  main.cuts.push_back(cut_below(0.5, polar(-0.8, 0.8)));  // fringe above the eyebrows
  st.parts = {main};
  return st;
}

}  // namespace

std::vector<std::string> style_preset_names() {
  return {"bob", "swept_back", "ponytail", "short_cut"};
}

HairStyle style_preset(std::string_view name, double density_scale) {
  if (!(density_scale > 0))
    fail("style preset: density_scale must be positive, got {}", density_scale);
  if (name == "bob") return bob(density_scale);
  if (name == "swept_back") return swept_back(density_scale);
  if (name == "ponytail") return ponytail(density_scale);
  if (name == "short_cut") return short_cut(density_scale);
  fail("unknown hairstyle preset \"{}\"; expected one of bob, swept_back, ponytail, short_cut",
       std::string(name));
}

}  // namespace follicle::hair
