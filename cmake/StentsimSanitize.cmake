# The sanitizer build (scripts/run-sanitizers.sh, build-asan): ASan and UBSan over the
# code that reads what a user gives (common/, segmentation_io's readers, solver/io and
# the checkpoint archive) and the fuzz harnesses that feed it bad input. Everything
# else keeps the Release flags of the normal build, so ccache serves it and the job
# stays short; the sanitizer runtimes are linked into every executable.
# Included before the project's folders (the link option must reach every target they
# add); stentsim_instrument_readers() is called after them.
option(STENTSIM_SANITIZE "Instrument the readers with -fsanitize=address,undefined" OFF)
# Eigen picks its allocator by __SANITIZE_ADDRESS__ (its own aligned blocks under ASan,
# glibc's malloc otherwise): instrumented code must use the one the rest of the build
# uses, or a vector allocated on one side is freed with the other's free.
set(STENTSIM_SANITIZE_FLAGS -O1 -g -fno-omit-frame-pointer -fsanitize=address,undefined -fno-sanitize-recover=all
    -DEIGEN_MALLOC_ALREADY_ALIGNED=1)
if(STENTSIM_SANITIZE)
  add_link_options(-fsanitize=address,undefined)
endif()

function(stentsim_instrument_readers)
  if(NOT STENTSIM_SANITIZE)
    return()
  endif()
  set(instrumented stentsim_common)
  if(STENTSIM_BUILD_TESTS)  # the fuzz harnesses
    list(APPEND instrumented test_segmentation_io_reader_fuzz test_fuzz_label_images test_fuzz_simvascular test_fuzz_yaml
         test_fuzz_checkpoint test_fuzz_vtk_xml)
  endif()
  foreach(target IN LISTS instrumented)
    target_compile_options(${target} PRIVATE ${STENTSIM_SANITIZE_FLAGS})
  endforeach()
  # The readers among segmentation_io's and the solver's sources (not CGAL's geometry, whose
  # instrumented compile alone would take longer than the job may).
  set(segmentation_readers surface_reader_vtk.cpp stl_binary.cpp legacy_vtk_ascii.cpp surface_checks.cpp triangle_surface.cpp
      simvascular_io.cpp label_image_vtk.cpp image_header_geometry.cpp image_header_checks.cpp tree_input.cpp)
  list(TRANSFORM segmentation_readers PREPEND ${PROJECT_SOURCE_DIR}/segmentation_io/)
  set_source_files_properties(${segmentation_readers} DIRECTORY ${PROJECT_SOURCE_DIR}/segmentation_io
    PROPERTIES COMPILE_OPTIONS "${STENTSIM_SANITIZE_FLAGS}")
  set(solver_readers io/generated_meshes.cpp io/selection.cpp io/scene.cpp io/solid_output.cpp io/results_writer.cpp
      terms/history_archive.cpp app/checkpoint.cpp)
  list(TRANSFORM solver_readers PREPEND ${PROJECT_SOURCE_DIR}/solver/)
  set_source_files_properties(${solver_readers} DIRECTORY ${PROJECT_SOURCE_DIR}/solver
    PROPERTIES COMPILE_OPTIONS "${STENTSIM_SANITIZE_FLAGS}")
endfunction()
