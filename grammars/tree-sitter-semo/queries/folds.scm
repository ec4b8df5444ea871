[
  (formation)
  (block)
  (mode_body)
  (main_body)
  (group_statement)
  (case_clause)
] @fold
