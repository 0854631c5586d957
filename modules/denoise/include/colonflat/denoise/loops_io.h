#pragma once
// The loops artifact moved to core (one loop type across stages): colonflat/core/loops.h.
#include "colonflat/core/loops.h"
#include "colonflat/denoise/denoise.h"
