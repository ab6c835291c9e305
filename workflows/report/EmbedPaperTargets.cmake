# Writes a C++ source whose embedded_paper_targets() returns the text of
# paper_targets.yaml, so a report compares with the paper without any file
# beside the binary. (cmake/EmbedText.cmake defines one fixed function for the
# example cases; both end up in the same binary, hence this separate script.)
# Usage: cmake -DOUT=file.cpp -DINPUT=paper_targets.yaml -P EmbedPaperTargets.cmake
file(READ "${INPUT}" content)
if(content MATCHES "\\)stentsim_embed\"")
  message(FATAL_ERROR "${INPUT} contains the raw-string delimiter )stentsim_embed\"")
endif()
set(text "// Generated from workflows/report/paper_targets.yaml by EmbedPaperTargets.cmake: do not edit.\n")
string(APPEND text "namespace stentsim::workflows::report {\nconst char* embedded_paper_targets() {\n")
string(APPEND text "  return R\"stentsim_embed(${content})stentsim_embed\";\n}\n}  // namespace stentsim::workflows::report\n")
file(WRITE "${OUT}.tmp" "${text}")
execute_process(COMMAND ${CMAKE_COMMAND} -E copy_if_different "${OUT}.tmp" "${OUT}")
