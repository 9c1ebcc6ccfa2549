(function () {
  'use strict';
  var player = document.getElementById('route-image');
  if (player) {
    var thumbs = Array.prototype.slice.call(document.querySelectorAll('.strip figure img'));
    var slider = document.getElementById('route-slider');
    var label = document.getElementById('route-label');
    var button = document.getElementById('route-play');
    var current = 0, timer = null;
    var show = function (i) {
      if (!thumbs.length) return;
      current = (i + thumbs.length) % thumbs.length;
      player.src = thumbs[current].getAttribute('src');
      slider.value = String(current);
      label.textContent = thumbs[current].getAttribute('data-label');
    };
    var stop = function () { if (timer) { clearInterval(timer); timer = null; button.textContent = 'Play'; } };
    button.addEventListener('click', function () {
      if (timer) { stop(); return; }
      button.textContent = 'Pause';
      timer = setInterval(function () { show(current + 1); }, 400);
    });
    slider.addEventListener('input', function () { stop(); show(parseInt(slider.value, 10)); });
    show(0);
  }
  if (location.hash !== '#selfcheck') return;
  var images = Array.prototype.slice.call(document.images);
  images.forEach(function (img) { img.loading = 'eager'; });
  var videos = Array.prototype.slice.call(document.querySelectorAll('video'));
  var waits = images.map(function (img) {
    if (img.complete && img.naturalWidth > 0) return Promise.resolve();
    return new Promise(function (done) {
      img.addEventListener('load', done);
      img.addEventListener('error', done);
      if (img.decode) img.decode().then(done, done);
    });
  }).concat(videos.map(function (video) {
    if (video.readyState >= 2) return Promise.resolve();
    return new Promise(function (done) {
      video.addEventListener('loadeddata', done);
      video.addEventListener('error', done);
      video.preload = 'auto';
      video.load();
    });
  }));
  Promise.all(waits).then(function () {
    var broken = images.filter(function (img) { return !(img.naturalWidth > 0); })
                       .map(function (img) { return img.getAttribute('src'); });
    var result = document.createElement('pre');
    result.id = 'vmap-selfcheck';
    result.textContent = JSON.stringify({
      images: images.length,
      broken: broken,
      videos: videos.length,
      broken_videos: videos.filter(function (v) { return !(v.readyState >= 2 && v.videoWidth > 0); })
                           .map(function (v) { return v.getAttribute('src'); }),
      match_figures: document.querySelectorAll('figure.match-figure').length,
      key_images: document.querySelectorAll('.strip figure').length,
      plots: document.querySelectorAll('svg.plot').length
    });
    document.body.appendChild(result);
  });
})();
