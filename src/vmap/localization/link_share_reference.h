#pragma once
// What the link share measures a comparison against (LocalizerOptions::min_link_share): per key image of the route,
// the verified matches it shares with its neighbours as a map of the matcher's usual spacing would link them.
//
// The share presumes that a frame between two key images shares more with each than they share with each other.
// That holds where the builder spaced the key images (a link is the last frame whose S still reached tau), not
// where every frame is a key image (`vmap build --tau 1` on a video): neighbours a frame apart are nearly the same
// image, and their link verifies about twice what a frame of another run verifies at the right key image, which
// the share then refuses. There the reference is the key image's link with the furthest key image on along the
// route whose S still reaches the usual tau: the link a map of that tau would hold.

#include <functional>
#include <optional>
#include <vector>

namespace vmap {

// What two key images share: S (as the map defines it) and the verified matches; nullopt when they could not be
// matched or verified.
struct SharedByKeys {
  double similarity = 0.0;
  int num_verified = 0;
};

// `link_after[p]`, one per route position: S and the verified matches of the map's link between route positions p and
// p + 1 (nullopt where the map has none, or none verified, and at the route's last position). `compare(p, q)` compares
// the key images at route positions p < q (q >= p + 2). Returns per route position the reference: the smaller of its
// forward and backward reference where both exist (0 where neither does). The forward reference of p is the verified
// count of the furthest q <= p + `max_reach` such that p and every q' in (p, q] reach S >= `tau` (the link p, p + 1 by
// its own S; a link missing ends the walk); the backward one that of the first position whose walk reached p. Where the
// link after p is below `tau`, p compares nothing: the map is spaced already, and its links are the reference, as
// before. The walks run on `threads` threads (ParallelFor; `compare` must be thread-safe then), with the same result
// for any number; an exception `compare` throws is rethrown.
std::vector<int> LinkShareReference(const std::vector<std::optional<SharedByKeys>>& link_after,
                                    const std::function<std::optional<SharedByKeys>(int p, int q)>& compare, double tau,
                                    int max_reach, int threads = 1);

}  // namespace vmap
