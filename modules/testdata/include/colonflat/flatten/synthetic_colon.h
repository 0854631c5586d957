#pragma once
// Old include path of the synthetic colon, kept so the tests that include it need no change; the
// generator lives in the test-support library colonflat_testdata (modules/testdata). New code
// includes "colonflat/testdata/synthetic_colon.h".
#include "colonflat/testdata/synthetic_colon.h"
