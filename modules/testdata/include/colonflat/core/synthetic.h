#pragma once
// Old include path of the synthetic meshes, kept so the tests that include it need no change; the
// meshes live in the test-support library colonflat_testdata (modules/testdata). New code
// includes "colonflat/testdata/synthetic.h".
#include "colonflat/testdata/synthetic.h"
