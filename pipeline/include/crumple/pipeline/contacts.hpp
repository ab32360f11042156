#pragma once
// A shot's contacts: the scene's [[colliders]] as a collider set
// that follows the animation, the contact options of the sheet models, and
// the depth measure the acceptance asks for at every frame.
#include <vector>

#include "crumple/cache/pcache.hpp"
#include "crumple/cache/pcache_contacts.hpp"
#include "crumple/io/animation.hpp"
#include "crumple/io/scene.hpp"
#include "crumple/sim/colliders.hpp"
#include "crumple/sim/elastic_sheet.hpp"

namespace crumple::pipeline {

// The scene's [[colliders]] as a sim::ColliderSet. Colliders with a node
// move rigidly with it (moveTo): a mesh by the node's motion since t = 0
// (its rest shape is the node's world-space mesh at t = 0), a box or sphere
// by the node's world transform (its position is an offset in the node's
// frame: a finger). Starts at the scene's first frame; empty when the scene
// has none. `scene` and `animation` must outlive it.
class SceneColliders {
 public:
  SceneColliders(const io::SceneSpec& scene, const io::AnimationScene* animation);
  bool empty() const { return set_.size() == 0; }
  const sim::ColliderSet& set() const { return set_; }
  // Name, material and friction of each collider (the cache's COLL block).
  const std::vector<cache::ColliderInfo>& info() const { return info_; }
  // Colliders with a node to time t (s).
  void moveTo(double t);

 private:
  const io::SceneSpec& scene_;
  const io::AnimationScene* animation_;
  sim::ColliderSet set_;
  std::vector<cache::ColliderInfo> info_;
};

// The contact options of a shot: its colliders (moved by the models'
// steps), self-contact as [contact] self says, paper on paper from
// [friction] paper, the paper's thickness as the contact distance.
// `colliders` must outlive the options.
sim::ContactOptions contactOptionsOf(const io::SceneSpec& scene, SceneColliders& colliders);

// How deep, in thicknesses, the deepest free vertex of a frame lies inside
// a collider (at their current poses) or inside another layer of the sheet
// (when self-contact is not off): the contact distance minus its distance
// over the distance, 0 when none is nearer than the distance. Handle
// vertices (the record's held ones) are the artist's to place and are left
// out. An edge through another layer (sim::SelfCrossing, which the
// vertex-triangle pairs cannot see) counts as 1 + how far it reaches past
// that layer, in thicknesses, as `inspect`'s self_depth does.
double contactDepth(const sim::ContactOptions& contact, const cache::FrameRecord& record);

}  // namespace crumple::pipeline
