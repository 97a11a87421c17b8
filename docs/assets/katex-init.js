// Renders the formulas pymdownx.arithmatex marked (class "arithmatex": \( ... \) inline,
// \[ ... \] displayed) with KaTeX, which docs_hooks/katex.py copies into assets/katex/.
document.addEventListener("DOMContentLoaded", function () {
  document.querySelectorAll(".arithmatex").forEach(function (el) {
    var tex = el.textContent.trim();
    var display = tex.startsWith("\\[");
    katex.render(tex.slice(2, -2), el, { displayMode: display, throwOnError: false });
  });
});
