#pragma once
// Paper as a thin elastic plate: stretch and bending stiffness from thickness,
// Young's modulus and Poisson ratio (Kirchhoff-Love plate theory).
// Header-only: the scene's paper preset fills it (io).
#include <string>

namespace crumple::sim {

// Defaults: the 70 g/m^2 office preset (assets/papers/office-70gsm.toml,
// where each number's source is given).
struct Material {
  std::string name = "office-70gsm";
  double thickness = 9.0e-5;     // m
  double density = 777.8;        // kg/m^3
  double youngsModulus = 4.0e9;  // Pa
  double poissonRatio = 0.25;

  double arealDensity() const { return density * thickness; }  // kg/m^2
  // Membrane (stretch) stiffness E h / (1 - nu^2), N/m.
  double stretchStiffness() const {
    return youngsModulus * thickness / (1.0 - poissonRatio * poissonRatio);
  }
  // Flexural rigidity E h^3 / (12 (1 - nu^2)), N m.
  double bendingStiffness() const {
    return youngsModulus * thickness * thickness * thickness /
           (12.0 * (1.0 - poissonRatio * poissonRatio));
  }

  bool operator==(const Material&) const = default;
};

}  // namespace crumple::sim
