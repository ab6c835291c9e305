# Writes a C++ source defining `const char* NAME = R"(...)"` for each input
# file, so the binary carries the examples that `stentsim init` writes.
# Usage: cmake -DOUT=file.cpp -DINPUTS="a.yaml;b.yaml" -P EmbedText.cmake
set(text "// Generated from examples/ by cmake/EmbedText.cmake: do not edit.\n#include <map>\n#include <string>\nnamespace stentsim::workflows {\nconst std::map<std::string, std::string>& embedded_examples() {\n  static const std::map<std::string, std::string> files = {\n")
string(REPLACE "|" ";" INPUTS "${INPUTS}")
foreach(f IN LISTS INPUTS)
  file(READ "${f}" content)
  get_filename_component(name "${f}" NAME)
  string(APPEND text "    {\"${name}\", R\"stentsim_embed(${content})stentsim_embed\"},\n")
endforeach()
string(APPEND text "  };\n  return files;\n}\n}  // namespace stentsim::workflows\n")
file(WRITE "${OUT}.tmp" "${text}")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
