// Which figures the browser could load, and at what size: the report's test reads these.
window.addEventListener('load', function () {
  var imgs = document.images, ok = 0, sizes = [];
  for (var i = 0; i < imgs.length; i++) {
    if (imgs[i].complete && imgs[i].naturalWidth > 0) ok++;
    imgs[i].setAttribute('data-natural-size', imgs[i].naturalWidth + 'x' + imgs[i].naturalHeight);
    imgs[i].setAttribute('data-shown-size', imgs[i].width + 'x' + imgs[i].height);
  }
  document.body.setAttribute('data-images-total', imgs.length);
  document.body.setAttribute('data-images-loaded', ok);
});
