#pragma once
// How fast this process runs the simulation's kind of work, against the
// machine the shot's cost figures were measured on (docs/RELIABILITY.md
// "The cost guard"). A budget of CPU seconds written as a number means
// different work on a machine twice as slow, or in a sanitized build that
// runs the same code five to ten times slower: a cost guard whose floors are
// absolute seconds stopped a sanitized tear sample whose dear frames are
// ordinary for that build. Budgets multiplied by machineSlowness() stay the
// same amount of work everywhere.
namespace crumple {

// The CPU seconds the reference workload took on the development machine
// (Release build, the figures in docs/RELIABILITY.md).
inline constexpr double kReferenceWorkSeconds = 0.009;

// The CPU seconds this process takes for the reference workload: an
// edge-length sweep with gradient scatter over a scrambled triangle-strip
// mesh, the memory and arithmetic pattern of the models' inner loops. The
// best of three runs, measured once per process (thread-safe; about 30 ms
// in a Release build).
double referenceWorkSeconds();

// referenceWorkSeconds() / kReferenceWorkSeconds: 1 on the development
// machine's Release build, about 2 on a machine half as fast, more in a
// sanitized build.
double machineSlowness();

}  // namespace crumple
