// (no include guard: included once per parameter list)
// Adds every parameter of a parameter list (a `.def` file; see core/params.h) to the ParamTable
// named `t`, bound to the field of the same name that params_as_fields.h declared:
//
//   ParamTable<DenoiseOptions> t;
//   #define COLONFLAT_PARAMS "colonflat/denoise/denoise_params.def"
//   #include "colonflat/core/params_as_rows.h"
//
// The option name is the member's name with '-' for '_' (max_loop_length -> --max-loop-length).
// COLONFLAT_PARAMS is undefined after.
#ifndef COLONFLAT_PARAMS
#error "define COLONFLAT_PARAMS as the quoted path of a parameter list before including params_as_rows.h"
#endif
#define CF_PARAM_OPTION_NAME(member) ::cf::param_option_name(#member)
#define CF_PARAM_MEMBER(member) &decltype(t)::options_type::member
#define CF_PARAM_UNPAREN(...) __VA_ARGS__
#define CF_REAL(member, default_value, unit, min, max, help) \
  t.real(CF_PARAM_OPTION_NAME(member), CF_PARAM_MEMBER(member), unit, help, min, max);
#define CF_INT(member, default_value, unit, min, max, help) \
  t.integer(CF_PARAM_OPTION_NAME(member), CF_PARAM_MEMBER(member), unit, help, min, max);
#define CF_TEXT(member, default_value, help) t.text(CF_PARAM_OPTION_NAME(member), CF_PARAM_MEMBER(member), help);
#define CF_CHOICE(member, default_value, choices, help) \
  t.choice(CF_PARAM_OPTION_NAME(member), CF_PARAM_MEMBER(member), {CF_PARAM_UNPAREN choices}, help);
#define CF_FLAG(member, default_value, help) t.flag(CF_PARAM_OPTION_NAME(member), CF_PARAM_MEMBER(member), help);
#include COLONFLAT_PARAMS
#undef CF_REAL
#undef CF_INT
#undef CF_TEXT
#undef CF_CHOICE
#undef CF_FLAG
#undef CF_PARAM_OPTION_NAME
#undef CF_PARAM_MEMBER
#undef CF_PARAM_UNPAREN
#undef COLONFLAT_PARAMS
