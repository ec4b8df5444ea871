[
  (formation)
  (block)
  (mode_body)
  (main_body)
  (group_statement)
] @indent.begin

[
  "}"
  "]]"
] @indent.branch @indent.end
