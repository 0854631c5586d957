# Helpers shared by every module.
#
#   colonflat_module(NAME <name> SOURCES ... DEPS ...)
#     builds static library colonflat_<name> from modules/<name>/src, public include dir
#     modules/<name>/include, and registers every stage it declares: each header
#     include/colonflat/<name>/<stage>_stage.h adds src/<stage>_stage.cpp to the library (listed
#     in SOURCES or not) and must declare `std::unique_ptr<cf::Stage> cf::make_<stage>_stage()`;
#     WITHOUT_STAGES leaves the module's stages out of this build. Each stage becomes the command
#     `colonflat <stage>` and a stage of `colonflat run` (chained by its ports). Nothing else to list.
#   colonflat_tests(NAME <name> SOURCES ... DEPS ... [LABELS ...])
#     builds <name>_tests from the given test sources and registers every GoogleTest case with ctest;
#     every test links the test-support library colonflat_testdata (modules/testdata).
#   colonflat_register_tool(FACTORY <fn> HEADER <header>)
#     adds a `colonflat <tool>` command (a function returning std::unique_ptr<cf::Tool>).
#   colonflat_register_stage(FACTORY <fn> HEADER <header>)
#     adds a pipeline stage whose header is not named <stage>_stage.h (a function returning
#     std::unique_ptr<cf::Stage>); it is also a command. A stage registered twice counts once.

set(COLONFLAT_WARNINGS -Wall -Wextra -Wno-unused-parameter)

function(colonflat_module)
  cmake_parse_arguments(M "WITHOUT_STAGES" "NAME" "SOURCES;DEPS" ${ARGN})
  # Every stage header <stage>_stage.h brings its src/<stage>_stage.cpp and is registered.
  set(_stages "")
  if(NOT M_WITHOUT_STAGES)
    file(GLOB _stage_headers CONFIGURE_DEPENDS
      ${CMAKE_CURRENT_SOURCE_DIR}/include/colonflat/${M_NAME}/*_stage.h)
    list(SORT _stage_headers)
    foreach(_header ${_stage_headers})
      get_filename_component(_file ${_header} NAME)
      string(REGEX REPLACE "_stage\\.h$" "" _stage ${_file})
      list(APPEND _stages ${_stage})
      if(NOT "src/${_stage}_stage.cpp" IN_LIST M_SOURCES)
        list(APPEND M_SOURCES src/${_stage}_stage.cpp)
      endif()
    endforeach()
  endif()
  add_library(colonflat_${M_NAME} STATIC ${M_SOURCES})
  target_include_directories(colonflat_${M_NAME} PUBLIC ${CMAKE_CURRENT_SOURCE_DIR}/include)
  target_link_libraries(colonflat_${M_NAME} PUBLIC ${M_DEPS})
  target_compile_options(colonflat_${M_NAME} PRIVATE ${COLONFLAT_WARNINGS})
  set_property(GLOBAL APPEND PROPERTY COLONFLAT_MODULE_LIBS colonflat_${M_NAME})
  foreach(_stage ${_stages})
    colonflat_register_stage(FACTORY cf::make_${_stage}_stage HEADER colonflat/${M_NAME}/${_stage}_stage.h)
  endforeach()
endfunction()

function(colonflat_tests)
  cmake_parse_arguments(T "" "NAME;TIMEOUT" "SOURCES;DEPS;LABELS" ${ARGN})
  if(NOT COLONFLAT_BUILD_TESTS)
    return()
  endif()
  add_executable(${T_NAME}_tests ${T_SOURCES})
  target_link_libraries(${T_NAME}_tests PRIVATE ${T_DEPS} colonflat_testdata GTest::gtest GTest::gtest_main GTest::gmock)
  target_include_directories(${T_NAME}_tests PRIVATE ${PROJECT_SOURCE_DIR}/modules/core/test/support)
  target_compile_definitions(${T_NAME}_tests PRIVATE
    COLONFLAT_SHARED_DIR="${COLONFLAT_SHARED_DIR}"
    COLONFLAT_SOURCE_DIR="${PROJECT_SOURCE_DIR}")
  if(NOT T_TIMEOUT)
    set(T_TIMEOUT 300)
  endif()
  include(GoogleTest)
  gtest_discover_tests(${T_NAME}_tests
    WORKING_DIRECTORY ${CMAKE_CURRENT_BINARY_DIR}
    PROPERTIES LABELS "${T_NAME};${T_LABELS}" TIMEOUT ${T_TIMEOUT}
    DISCOVERY_TIMEOUT 60)
endfunction()

function(colonflat_register_tool)
  cmake_parse_arguments(R "" "FACTORY;HEADER" "" ${ARGN})
  set_property(GLOBAL APPEND PROPERTY COLONFLAT_TOOL_FACTORIES "${R_FACTORY}")
  set_property(GLOBAL APPEND PROPERTY COLONFLAT_TOOL_HEADERS "${R_HEADER}")
endfunction()

function(colonflat_register_stage)
  cmake_parse_arguments(R "" "FACTORY;HEADER" "" ${ARGN})
  get_property(_known GLOBAL PROPERTY COLONFLAT_STAGE_FACTORIES)
  if("${R_FACTORY}" IN_LIST _known)
    return()
  endif()
  set_property(GLOBAL APPEND PROPERTY COLONFLAT_STAGE_FACTORIES "${R_FACTORY}")
  set_property(GLOBAL APPEND PROPERTY COLONFLAT_TOOL_HEADERS "${R_HEADER}")
endfunction()
