# geodex_cgal_reference: the CGAL Surface_mesh_shortest_path wrapper (tests/util/cgal_reference.h,
# tests/cgal/cgal_reference.cc) as a small static library, linked by cgal_tests and geodex_bench.
#
# Included from tests/CMakeLists.txt and from bench/CMakeLists.txt; the target is defined once,
# whatever GEODEX_BUILD_TESTS says (it needs CGAL, not GoogleTest). CGAL is a PRIVATE dependency:
# its headers (and -frounding-math) stay confined to cgal_reference.cc. Without CGAL the target is
# simply absent; callers test `if(TARGET geodex_cgal_reference)`.
include_guard(GLOBAL)

find_package(CGAL CONFIG QUIET)
if(CGAL_FOUND)
  add_library(geodex_cgal_reference STATIC ${PROJECT_SOURCE_DIR}/tests/cgal/cgal_reference.cc)
  # The header is included as "util/cgal_reference.h".
  target_include_directories(geodex_cgal_reference PUBLIC ${PROJECT_SOURCE_DIR}/tests)
  target_link_libraries(geodex_cgal_reference PUBLIC geodex_core PRIVATE CGAL::CGAL)
else()
  message(WARNING "CGAL not found: no CGAL reference (CGAL tests and the bench's CGAL column)")
endif()
