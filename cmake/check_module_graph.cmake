# cmake -DGRAPH=<build>/module_graph.txt -DDOC=docs/architecture.md -P check_module_graph.cmake
#
# Fails unless the lines between "<!-- module-graph:begin -->" and "<!-- module-graph:end -->" of
# the page (inside a fenced block) are, apart from the fence and blank lines, the lines of GRAPH,
# which finecap_write_module_graph wrote from what the targets really link.
file(READ ${GRAPH} graph)
file(READ ${DOC} doc)
string(FIND "${doc}" "<!-- module-graph:begin -->" begin)
string(FIND "${doc}" "<!-- module-graph:end -->" end)
if(begin EQUAL -1 OR end EQUAL -1 OR end LESS begin)
  message(FATAL_ERROR "${DOC}: no block between <!-- module-graph:begin --> and "
    "<!-- module-graph:end -->")
endif()
math(EXPR length "${end} - ${begin}")
string(SUBSTRING "${doc}" ${begin} ${length} block)
string(REPLACE "\n" ";" block_lines "${block}")
set(drawn "")
foreach(line ${block_lines})
  string(STRIP "${line}" line)
  if(line STREQUAL "" OR line MATCHES "^```" OR line MATCHES "^<!--")
    continue()
  endif()
  string(APPEND drawn "${line}\n")
endforeach()
if(NOT drawn STREQUAL graph)
  message(FATAL_ERROR "${DOC}: the module graph it lists is\n${drawn}\nbut the CMake targets "
    "link\n${graph}\nUpdate the page's block (between the module-graph markers) to the second.")
endif()
message(STATUS "module graph of ${DOC} matches the targets:\n${graph}")
