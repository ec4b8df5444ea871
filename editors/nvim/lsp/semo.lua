-- The SeMo language server for Neovim 0.11+: put editors/nvim on 'runtimepath', then
--   vim.lsp.enable('semo')
-- It serves missions (filetype `semo`) and, among XML files, only strategy, robot and
-- task-graph files, among JSON files only scenarios: for other XML or JSON buffers root_dir
-- never calls on_dir, so it does not attach.
local semo = require('semo')

return {
  cmd = { 'semo', 'lsp' },
  filetypes = { 'semo', 'xml', 'json' },
  root_dir = function(bufnr, on_dir)
    if semo.is_semo_buffer(bufnr) then
      on_dir(semo.root_dir(vim.api.nvim_buf_get_name(bufnr)))
    end
  end,
}
