// (no include guard: included once per parameter list)
// Declares the fields of an Options struct from a parameter list (a `.def` file, one line per
// parameter; see core/params.h). Use inside the struct:
//
//   struct DenoiseOptions {
//   #define COLONFLAT_PARAMS "colonflat/denoise/denoise_params.def"
//   #include "colonflat/core/params_as_fields.h"
//   };
//
// Each line of the list gives a field `type member = default;`. COLONFLAT_PARAMS is undefined after.
#ifndef COLONFLAT_PARAMS
#error "define COLONFLAT_PARAMS as the quoted path of a parameter list before including params_as_fields.h"
#endif
#define CF_REAL(member, default_value, unit, min, max, help) double member = default_value;
#define CF_INT(member, default_value, unit, min, max, help) int member = default_value;
#define CF_TEXT(member, default_value, help) std::string member = default_value;
#define CF_CHOICE(member, default_value, choices, help) std::string member = default_value;
#define CF_FLAG(member, default_value, help) bool member = default_value;
#include COLONFLAT_PARAMS
#undef CF_REAL
#undef CF_INT
#undef CF_TEXT
#undef CF_CHOICE
#undef CF_FLAG
#undef COLONFLAT_PARAMS
