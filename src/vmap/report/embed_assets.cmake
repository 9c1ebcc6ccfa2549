# Turns the report's asset files into C++ at build time: run as
#   cmake -DOUTPUT=file.cc -DASSETS="name1=path1;name2=path2" -P embed_assets.cmake
# and writes, for each NAME=PATH, a function `std::string_view NAME()` in namespace vmap::report that returns
# the file's bytes. The bytes are written as numbers, so any content (quotes, backslashes, ")", non-ASCII,
# NUL) is embedded exactly.
if(NOT OUTPUT OR NOT ASSETS)
  message(FATAL_ERROR "embed_assets.cmake needs -DOUTPUT=... and -DASSETS=name=path;...")
endif()
set(code "// Generated at build time by src/vmap/report/embed_assets.cmake from src/vmap/report/assets/. Do not edit.\n\n")
string(APPEND code "#include \"vmap/report/report_assets.h\"\n\nnamespace vmap::report {\nnamespace {\n\n")
set(functions "")
foreach(asset IN LISTS ASSETS)
  string(REGEX MATCH "^([A-Za-z_][A-Za-z0-9_]*)=(.+)$" matched "${asset}")
  if(NOT matched)
    message(FATAL_ERROR "embed_assets.cmake: '${asset}' is not NAME=PATH")
  endif()
  set(name "${CMAKE_MATCH_1}")
  set(path "${CMAKE_MATCH_2}")
  file(READ "${path}" hex HEX)
  get_filename_component(file_name "${path}" NAME)
  string(LENGTH "${hex}" hex_length)
  math(EXPR size "${hex_length} / 2")
  # 0xNN per byte, a line of code per line of the file; a final 0 keeps the array non-empty for an empty file.
  string(REGEX REPLACE "([0-9a-f][0-9a-f])" "0x\\1," bytes "${hex}")
  string(REPLACE "0x0a," "0x0a,\n  " bytes "${bytes}")
  string(APPEND code "// assets/${file_name}\nconstexpr unsigned char k${name}[] = {\n  ${bytes}0};\n\n")
  string(APPEND functions "std::string_view ${name}() { return {reinterpret_cast<const char*>(k${name}), ${size}}; }\n")
endforeach()
string(APPEND code "}  // namespace\n\n${functions}\n}  // namespace vmap::report\n")
# Rewritten only when it changes, so that an unchanged asset recompiles nothing.
set(previous "")
if(EXISTS "${OUTPUT}")
  file(READ "${OUTPUT}" previous)
endif()
if(NOT previous STREQUAL code)
  file(WRITE "${OUTPUT}" "${code}")
endif()
