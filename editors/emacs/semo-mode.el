;;; semo-mode.el --- Major mode for SeMo mission scripts  -*- lexical-binding: t; -*-

;; Version: 0.1.0
;; Package-Requires: ((emacs "27.1"))
;; Keywords: languages
;; SPDX-License-Identifier: MIT

;;; Commentary:

;; Editing SeMo missions (`.mission'): robots grouped into teams, composite services on
;; plans, modes, and a `main' block per team that switches modes on events.
;;
;; - font-lock for keywords, periods (`2 SEC'), team/plan/service headers, modes and events;
;; - `#' comments (M-;), and indentation as `semo fmt' lays missions out (two spaces per
;;   block level, one more for an unbraced `if'/`loop'/`group' body and for `catch' lines);
;; - the language server through eglot: `M-x eglot' (or `eglot-ensure' in
;;   `semo-mode-hook') runs `semo lsp' for diagnostics, completion, hover, rename...
;;
;; Setup (see the README):
;;   (add-to-list 'load-path "/path/to/semo/editors/emacs")
;;   (require 'semo-mode)
;;   (add-hook 'semo-mode-hook #'eglot-ensure)

;;; Code:

(defgroup semo nil
  "SeMo mission scripts."
  :group 'languages
  :prefix "semo-")

(defcustom semo-indent-offset 2
  "Spaces per indentation level in missions (`semo fmt' uses 2)."
  :type 'integer
  :safe #'integerp)

(defcustom semo-server-command '("semo" "lsp")
  "The language server's command line, for eglot.
Set it before loading eglot (or this file) if `semo' is not on the PATH."
  :type '(repeat string))

(defconst semo--name "[A-Za-z_][A-Za-z0-9_]*"
  "An identifier.")

(defconst semo-keywords
  '("if" "else" "loop" "repeat" "throw" "broadcast" "send" "receive" "publish" "subscribe" "set" "def"
    "main" "case" "catch" "default" "mode" "group" "leader" "others" "instance" "of" "capable"
    "timeout" "and" "or" "not")
  "Reserved words of the mission language (besides `true', `false' and `OFF').")

(defvar semo-mode-syntax-table
  (let ((table (make-syntax-table)))
    (modify-syntax-entry ?# "<" table)
    (modify-syntax-entry ?\n ">" table)
    (modify-syntax-entry ?\" "\"" table)
    (modify-syntax-entry ?\\ "\\" table)
    (modify-syntax-entry ?_ "_" table)
    (modify-syntax-entry ?' "." table)
    (dolist (c '(?= ?< ?> ?! ?& ?| ?: ?, ?\; ?.))
      (modify-syntax-entry c "." table))
    table)
  "Syntax table of `semo-mode': `#' comments, double-quoted strings, brackets.")

(defun semo--names (&rest parts)
  "A regexp of PARTS where the symbol `name' stands for a captured identifier."
  (mapconcat (lambda (part) (if (eq part 'name) (concat "\\(" semo--name "\\)") part))
             parts ""))

(defvar semo-font-lock-keywords
  `(;; Team.Plan.Service {
    (,(semo--names "\\_<" 'name "\\s-*\\.\\s-*" 'name "\\s-*\\.\\s-*" 'name "\\s-*{")
     (1 font-lock-type-face) (2 font-lock-variable-name-face)
     (3 font-lock-function-name-face))
    ;; Team.main
    (,(semo--names "\\_<" 'name "\\s-*\\.\\s-*\\(main\\)\\_>")
     (1 font-lock-type-face) (2 font-lock-keyword-face))
    ;; Team.MODE {
    (,(semo--names "\\_<" 'name "\\s-*\\.\\s-*" 'name "\\s-*{")
     (1 font-lock-type-face) (2 font-lock-constant-face))
    ;; def function
    (,(semo--names "\\_<\\(def\\)\\s-+" 'name)
     (1 font-lock-keyword-face) (2 font-lock-function-name-face))
    ;; Team: RobotType robot, ... (a team declaration)
    (,(semo--names "^\\s-*{?\\s-*" 'name "\\s-*:\\s-*" 'name "\\s-+" 'name)
     (1 font-lock-type-face) (2 font-lock-type-face) (3 font-lock-variable-name-face))
    ;; throw EVENT, catch (EVENT)
    (,(semo--names "\\_<\\(throw\\)\\s-+" 'name)
     (1 font-lock-keyword-face) (2 font-lock-constant-face))
    (,(semo--names "\\_<\\(catch\\)\\s-*(\\s-*" 'name)
     (1 font-lock-keyword-face) (2 font-lock-constant-face))
    ;; case (MODE), mode = MODE
    (,(semo--names "\\_<\\(case\\)\\s-*(\\s-*" 'name)
     (1 font-lock-keyword-face) (2 font-lock-constant-face))
    (,(semo--names "\\_<\\(mode\\)\\s-*=\\s-*" 'name)
     (1 font-lock-keyword-face) (2 font-lock-constant-face))
    ;; set(Plan, Service or OFF)
    (,(semo--names "\\_<\\(set\\)\\s-*(\\s-*" 'name "\\s-*,\\s-*" 'name)
     (1 font-lock-keyword-face) (2 font-lock-variable-name-face)
     (3 font-lock-function-name-face))
    ;; 2 SEC, 500 msec
    ("-?\\_<[0-9]+\\(?:\\.[0-9]+\\)?\\s-*\\([Mm][Ss][Ee][Cc]\\|[Ss][Ee][Cc]\\|[Mm][Ii][Nn]\\|[Hh][Oo][Uu][Rr]\\)\\_>"
     (1 font-lock-builtin-face))
    (,(regexp-opt semo-keywords 'symbols) . font-lock-keyword-face)
    (,(regexp-opt '("true" "false" "OFF") 'symbols) . font-lock-constant-face)
    (,(regexp-opt '("USER" "user") 'symbols) . font-lock-builtin-face)
    ;; built-in service or function call: move(...)
    (,(semo--names "\\_<" 'name "\\s-*(") (1 font-lock-function-name-face keep))
    ("\\[\\[\\|\\]\\]" . font-lock-builtin-face))
  "Highlighting of `semo-mode'.")

;;; Indentation

(defun semo--open-brackets ()
  "The open brackets around the start of this line; `[[' counts once."
  (let ((opens (save-excursion (nth 9 (syntax-ppss (line-beginning-position)))))
        (kept nil))
    (dolist (pos opens)
      (unless (and kept (= pos (1+ (car kept)))
                   (eq (char-after pos) ?\[) (eq (char-after (car kept)) ?\[))
        (push pos kept)))
    (nreverse kept)))

(defun semo--previous-code-line ()
  "Move to the previous line holding code; nil at the start of the buffer."
  (let (found)
    (while (and (not found) (zerop (forward-line -1)))
      (back-to-indentation)
      (unless (or (eolp) (eq (char-after) ?#) (nth 4 (syntax-ppss)))
        (setq found t)))
    found))

(defun semo--ends-with-comma-p ()
  "Whether this line's code ends with a comma (outside a comment)."
  (save-excursion
    (end-of-line)
    (let ((comment (nth 8 (syntax-ppss))))
      (when (and comment (nth 4 (syntax-ppss)))
        (goto-char comment)))
    (skip-chars-backward " \t")
    (eq (char-before) ?,)))

;; A statement's body may go unbraced on the next line: `if (...)', `else', `loop (...)',
;; `group (...)', `leader (...)', `others'.
(defun semo--unbraced-header-p ()
  "Whether this line ends with a header whose body is on the next line."
  (save-excursion
    (back-to-indentation)
    (let ((end (line-end-position)))
      (when (looking-at "}\\s-*")
        (goto-char (match-end 0)))
      (or (when (looking-at "\\(?:else\\s-+\\)?\\(?:if\\|loop\\|group\\|leader\\)\\s-*(")
            (goto-char (1- (match-end 0)))
            (and (ignore-errors (forward-sexp) t)
                 (<= (point) end)
                 (looking-at "\\s-*\\(?:#.*\\)?$")))
          (looking-at "\\(?:else\\|others\\)\\s-*\\(?:#.*\\)?$")
          ;; `if (a) {} else' at the end of a line
          (and (re-search-forward "\\_<else\\s-*\\(?:#.*\\)?$" end t)
               (not (nth 8 (syntax-ppss (match-beginning 0)))))))))

(defun semo--indentation ()
  "The column where the current line's code belongs."
  (save-excursion
    (back-to-indentation)
    (let* ((opens (semo--open-brackets))
           (closer (looking-at "}\\|]]\\|)"))
           (depth (- (length opens) (if closer 1 0)))
           (innermost (car (last opens)))
           (base (* semo-indent-offset (max depth 0))))
      (cond
       ;; A comment line goes with the code after it (inside a block it closes).
       ((looking-at "#")
        (forward-line 1)
        (while (and (not (eobp))
                    (progn (back-to-indentation) (or (eolp) (looking-at "#"))))
          (forward-line 1))
        (back-to-indentation)
        (if (eobp)
            base
          (+ (semo--indentation)
             (if (looking-at "}\\|]]\\|)") semo-indent-offset 0))))
       ;; `catch' lines sit under their `case' in a main block.
       ((and (looking-at "catch\\_>") innermost
             (save-excursion
               (goto-char innermost)
               (looking-back "\\.\\s-*main\\s-*" (line-beginning-position))))
        (+ base semo-indent-offset))
       ;; `else' goes under the nearest `if' of the same block (the dangling-else rule).
       ((looking-at "else\\_>")
        (or (save-excursion
              (let (column)
                (while (and (not column) (semo--previous-code-line))
                  (when (and (equal (semo--open-brackets) opens)
                             (looking-at "\\(?:}\\s-*\\)?\\(?:else\\s-+\\)?if\\_>"))
                    (setq column (current-indentation))))
                column))
            base))
       ;; A team declaration broken after a comma (or a colon): its robots one level in.
       ((and (not closer)
             (save-excursion
               (and (semo--previous-code-line)
                    (equal (semo--open-brackets) opens)
                    (looking-at (concat semo--name "\\s-*:\\s-*\\(?:#.*\\)?$")))))
        (save-excursion
          (semo--previous-code-line)
          (+ (current-indentation) semo-indent-offset)))
       ((and (not closer)
             (save-excursion
               (and (semo--previous-code-line)
                    (equal (semo--open-brackets) opens)
                    (semo--ends-with-comma-p))))
        (save-excursion
          (semo--previous-code-line)
          (current-indentation)))
       ;; The body of an unbraced `if (...)', `else', `loop (...)', `group (...)', `others'.
       ((and (not closer)
             (not (looking-at "{"))
             (save-excursion
               (and (semo--previous-code-line)
                    (equal (semo--open-brackets) opens)
                    (semo--unbraced-header-p))))
        (save-excursion
          (semo--previous-code-line)
          (+ (current-indentation) semo-indent-offset)))
       (t base)))))

(defun semo-indent-line ()
  "Indent the current line as `semo fmt' would."
  (interactive)
  (let ((column (semo--indentation))
        (offset (- (current-column) (current-indentation))))
    (indent-line-to column)
    (when (> offset 0)
      (move-to-column (+ column offset)))))

;;;###autoload
(define-derived-mode semo-mode prog-mode "SeMo"
  "Major mode for SeMo mission scripts.

\\{semo-mode-map}"
  :syntax-table semo-mode-syntax-table
  (setq-local comment-start "# ")
  (setq-local comment-start-skip "#+\\s-*")
  (setq-local comment-end "")
  (setq-local font-lock-defaults '(semo-font-lock-keywords))
  (setq-local indent-line-function #'semo-indent-line)
  (setq-local indent-tabs-mode nil)
  (setq-local electric-indent-chars (append '(?} ?\]) electric-indent-chars)))

;;;###autoload
(add-to-list 'auto-mode-alist '("\\.mission\\'" . semo-mode))

;; The language server, for eglot (`M-x eglot' in a mission, or `eglot-ensure' in the hook).
(defvar eglot-server-programs)
(with-eval-after-load 'eglot
  (add-to-list 'eglot-server-programs `(semo-mode . ,semo-server-command)))

(provide 'semo-mode)
;;; semo-mode.el ends here
