-- Neovim as the language client of `mercmac lsp`: run by tests/lsp/test_lsp_neovim.py as
-- `nvim --headless -u NONE -l` would (0.7 has no -l: `-c "luafile ..."`). The spec (JSON in
-- $MERCMAC_NVIM_SPEC) names the server command, the root folder, and the requests to send,
-- each for one file; Neovim's own client starts the server, says initialize with its own
-- capabilities, opens each file (didOpen), and sends each request; the answers are written
-- as JSON to the spec's `out`. Works on Neovim 0.7 (Debian 12) and later.
local spec = vim.fn.json_decode(vim.fn.readfile(os.getenv("MERCMAC_NVIM_SPEC")))
local answers = { requests = {} }
local ok, failure = pcall(function()
  local id = vim.lsp.start_client({
    name = "mercmac",
    cmd = spec.server,
    root_dir = spec.root,
  })
  assert(id, "the client did not start")
  local client = vim.lsp.get_client_by_id(id)
  assert(vim.wait(30000, function() return client.initialized end, 20),
         "no answer to initialize")
  answers.capabilities = client.server_capabilities or client.resolved_capabilities
  for index, request in ipairs(spec.requests) do
    vim.cmd("edit " .. vim.fn.fnameescape(request.file))
    local buffer = vim.api.nvim_get_current_buf()
    vim.lsp.buf_attach_client(buffer, id)
    local params = request.params or {}
    if not request.workspace then  -- workspace/symbol names no document
      params.textDocument = { uri = vim.uri_from_bufnr(buffer) }
    end
    local results, err = vim.lsp.buf_request_sync(buffer, request.method, params, 30000)
    local answer = results and results[id] or { error = err or "no answer" }
    answers.requests[index] = { method = request.method, result = answer.result, error = answer.err }
  end
end)
answers.failure = (not ok) and tostring(failure) or vim.NIL
vim.fn.writefile({ vim.fn.json_encode(answers) }, spec.out)
vim.cmd("qall!")
