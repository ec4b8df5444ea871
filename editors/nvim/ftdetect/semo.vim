" SeMo missions. Strategy, robot and task-graph files stay `xml` (the language server
" attaches to them by name, see lua/semo/init.lua).
autocmd BufRead,BufNewFile *.mission setfiletype semo
