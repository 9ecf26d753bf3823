// Loaded first by a copy of a page under test (tests/integration/pages_render.sh): records every
// failed load (images, video, styles) and every console error or warning, and when the page has
// loaded writes what it found into the data-rl-probe attribute of <html>, which
// `chromium --dump-dom` prints: "images=N broken=N svgs=N errors=N" and one line per error.
(function () {
  'use strict';
  var errors = [];
  window.addEventListener('error', function (e) {
    var t = e.target;
    if (t && t !== window && (t.src || t.href)) {
      errors.push('load failed: ' + (t.currentSrc || t.src || t.href));
    } else {
      errors.push('script error: ' + e.message);
    }
  }, true);
  ['error', 'warn'].forEach(function (level) {
    var original = console[level];
    console[level] = function () {
      errors.push('console.' + level + ': ' + Array.prototype.join.call(arguments, ' '));
      original.apply(console, arguments);
    };
  });
  window.addEventListener('load', function () {
    var images = Array.prototype.slice.call(document.images);
    var broken = images.filter(function (i) { return !(i.complete && i.naturalWidth > 0); });
    broken.forEach(function (i) { errors.push('image not shown: ' + i.src); });
    document.documentElement.setAttribute('data-rl-probe',
        'images=' + images.length + ' broken=' + broken.length + ' svgs=' +
        document.querySelectorAll('svg').length + ' errors=' + errors.length +
        (errors.length ? '\n' + errors.join('\n') : ''));
  });
})();
