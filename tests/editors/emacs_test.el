;;; emacs_test.el --- semo-mode and eglot against the real `semo lsp'  -*- lexical-binding: t; -*-

;; Run by tests/editors.rs: emacs --batch -Q -l emacs_test.el, with SEMO_BIN (the binary),
;; SEMO_REPO (the checkout) and SEMO_WORKSPACE (a copy of tests/editors/workspace).
;; Each check prints one line; a failure exits with status 1 and says what was expected.

(require 'package)
;; Debian's elpa-eglot (with newer project and xref); -Q skips the startup that adds it.
(add-to-list 'package-directory-list "/usr/share/emacs/site-lisp/elpa")
(package-initialize)

(defun semo-test-fail (format-string &rest args)
  (princ (concat "FAILED: " (apply #'format format-string args) "\n") #'external-debugging-output)
  (kill-emacs 1))

(defun semo-test-report (format-string &rest args)
  (princ (concat (apply #'format format-string args) "\n")))

(condition-case err
    (let ((workspace (getenv "SEMO_WORKSPACE")))
      ;; As the README says: the server command (here the built binary), then the mode.
      (setq semo-server-command (list (getenv "SEMO_BIN") "lsp"))
      (load (expand-file-name "editors/emacs/semo-mode.el" (getenv "SEMO_REPO")) nil t)
      (require 'eglot)
      (unless (assq 'semo-mode eglot-server-programs)
        (semo-test-fail "semo-mode has no eglot-server-programs entry"))

      (find-file (expand-file-name "rover.mission" workspace))
      (unless (eq major-mode 'semo-mode)
        (semo-test-fail "a .mission opens in %s" major-mode))
      (semo-test-report "mode: %s" major-mode)

      ;; 1. Font-lock: the event after `throw' and the mode after `mode ='.
      (font-lock-ensure)
      (goto-char (point-min))
      (search-forward "throw GO")
      (let ((event-face (get-text-property (1- (point)) 'face))
            (throw-face (get-text-property (- (point) 5) 'face)))
        (semo-test-report "faces at `throw GO': %s / %s" throw-face event-face)
        (unless (and (eq throw-face 'font-lock-keyword-face)
                     (eq event-face 'font-lock-constant-face))
          (semo-test-fail "`throw GO' is not highlighted as keyword and constant")))

      ;; 2. Indentation: the file, flattened, indents back to itself (the `semo fmt' layout).
      (let ((text (buffer-string)))
        (with-temp-buffer
          (insert text)
          (semo-mode)
          (goto-char (point-min))
          (while (re-search-forward "^[ \t]+" nil t) (replace-match ""))
          (let ((inhibit-message t)) (indent-region (point-min) (point-max)))
          (unless (equal (buffer-string) text)
            (semo-test-fail "indent-region changed the mission:\n%s" (buffer-string))))
        (semo-test-report "indent-region: unchanged"))

      ;; 3. The diagnostic of the misspelt mode, from `semo lsp' through eglot and flymake.
      (apply #'eglot (eglot--guess-contact))
      (unless (eglot-current-server)
        (semo-test-fail "eglot did not connect to %S" semo-server-command))
      (flymake-start)
      (let ((deadline (+ (float-time) 30)))
        (while (and (null (flymake-diagnostics)) (< (float-time) deadline))
          (accept-process-output nil 0.1)
          (flymake-start)))
      (let ((diagnostic (car (flymake-diagnostics))))
        (unless diagnostic
          (semo-test-fail "no diagnostic within 30 s"))
        (let* ((beg (flymake-diagnostic-beg diagnostic))
               (line (line-number-at-pos beg))
               (column (save-excursion (goto-char beg) (1+ (current-column))))
               (text (flymake-diagnostic-text diagnostic)))
          (semo-test-report "diagnostic: %d:%d %s: %s" line column
                            (flymake-diagnostic-type diagnostic) text)
          (unless (and (= line 24) (= column 24))
            (semo-test-fail "the diagnostic is not on `MOVNG' (line 24, column 24)"))
          (unless (string-match-p "MOVING" text)
            (semo-test-fail "the message does not suggest `MOVING'"))
          (unless (eq (flymake-diagnostic-type diagnostic) 'eglot-error)
            (semo-test-fail "the diagnostic is not an error"))))

      (let ((inhibit-message t)) (eglot-shutdown (eglot-current-server)))
      (kill-emacs 0))
  (error (semo-test-fail "%s" (error-message-string err))))

;;; emacs_test.el ends here
