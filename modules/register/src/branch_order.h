#pragma once
// Several side branches of colon length hanging at one neck of a band (docs/register.md, Pieces
// step 3): flatten cuts a loop of the colon off where its walls touch, and the loop can come out as
// two branches meeting at their tips.
// The colon is one tube: it leaves the band at the neck, runs through every stretch hanging there
// end to end and goes on along the band after the neck. Inserted each from its own neck end in
// segment-id order, the later one could come first (test TwoBranchesAtOneNeckAreInsertedInTheirCourse:
// 70-80 mm off); the order and directions that make the shortest such tour are taken.
#include <vector>

#include "colonflat/register/pieces.h"

namespace cf {

// For each band of `pieces`, its long branches hanging on it directly (ColonPiece::on_band; a branch
// of a branch hangs along its parent, not at the neck) whose necks
// lie within `same_neck_mm` of each other along the band form one group; a group of two or more gets
// the order (ColonPiece::neck_rank) and directions (flipped) of the shortest tour: from the band's
// centre `same_neck_mm` / 2 before the group's first neck, through each branch from one end to the
// other, to the band's centre that far after its last neck (ties keep the directions the branches
// have and the order by neck, then segment id). The group's members then share its first neck
// (attach_mm). Single branches are left as they are. At most 6 branches per group are ordered.
void order_branches_at_necks(std::vector<ColonPiece>& pieces, double same_neck_mm);

}  // namespace cf
