"use strict";
// Records every error the page raises, from the first script on, so the self-test
// (opened with #selftest in the URL) can report them. Harmless in normal viewing:
// errors still reach the console as usual.

const SelftestHooks = (() => {
  const errors = [];

  // Uncaught exceptions, including syntax errors in later script elements.
  window.onerror = (message, source, line, column) => {
    errors.push("uncaught: " + message + " (" + source + ":" + line + ":" + column + ")");
    return false;
  };

  window.addEventListener("unhandledrejection", (event) => {
    errors.push("unhandled rejection: " + String(event.reason));
  });

  // console.error calls made by the page's own scripts.
  const originalError = console.error.bind(console);
  console.error = (...args) => {
    errors.push("console.error: " + args.map(String).join(" "));
    originalError(...args);
  };

  return {
    errors,
    /** True when the page was opened with #selftest. */
    active: window.location.hash === "#selftest",
  };
})();
