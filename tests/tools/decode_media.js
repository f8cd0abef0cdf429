// For tests/tools/chromium_eval.py: decodes every image and video of the page. Each video is played
// to its end in a fresh element of its own (muted, 8x speed), so the page's own looping copy does
// not add to the count; totalVideoFrames counts every frame decoded, shown or dropped.
(async () => {
  const images = Array.from(document.images);
  const videos = await Promise.all(Array.from(document.querySelectorAll('video')).map(shown => new Promise((resolve, reject) => {
    const v = document.createElement('video');
    v.addEventListener('ended', () => resolve({
      width: v.videoWidth, height: v.videoHeight, frames: v.getVideoPlaybackQuality().totalVideoFrames,
      declaredFrames: Number(shown.dataset.frames), duration: v.duration}));
    v.addEventListener('error', () => reject(new Error('video: ' + (v.error ? v.error.message : 'cannot decode'))));
    v.muted = true;
    v.src = shown.currentSrc || shown.src;
    v.playbackRate = 8;
    v.play().catch(reject);
  })));
  return {images: images.length, imagesDecoded: images.filter(i => i.complete && i.naturalWidth > 0).length, videos};
})()
