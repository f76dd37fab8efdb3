// Opens a report.html in Debian's chromium (headless, driven by Playwright) and checks its 3D
// view: no console error and no uncaught exception, the view drawn, each class that has cells
// shows its colour in a screenshot of the canvas, and hiding a class takes its colour away.
// Usage: node check_view3d.cjs REPORT_HTML SCREENSHOT_PNG. Exit 1 with what failed.
'use strict';
const fs = require('fs');
const path = require('path');
const {chromium} = require('playwright-core');

// A pixel is a class's colour when each channel is within this of it: the top faces are drawn in
// the colour itself, antialiasing and up to two translucent surfaces (opacity 0.12 each, grey
// 180) in front shift a channel by at most about 0.23 * 210 = 48.
const kTolerance = 48;
// A class is seen when a cell's top face shows: at the view's framing a 5 cm cell is about 5 px
// across, so 4 pixels are less than one cell.
const kMinPixels = 4;

function fail(message) {
  console.error(`check_view3d: ${message}`);
  process.exit(1);
}

// How many pixels of the PNG `png` match each of `colours` ("#rrggbb"), counted in the page.
function countColours(page, png, colours) {
  return page.evaluate(async ({base64, colours, tolerance}) => {
    const image = new Image();
    image.src = `data:image/png;base64,${base64}`;
    await image.decode();
    const canvas = document.createElement('canvas');
    canvas.width = image.width;
    canvas.height = image.height;
    const context = canvas.getContext('2d');
    context.drawImage(image, 0, 0);
    // The element's box may take in a row of the page at its edge: 2 pixels around are left out.
    const px = context.getImageData(2, 2, canvas.width - 4, canvas.height - 4).data;
    const rgb = colours.map((c) => [1, 3, 5].map((i) => parseInt(c.substr(i, 2), 16)));
    const counts = colours.map(() => 0);
    for (let i = 0; i < px.length; i += 4) {
      rgb.forEach((c, k) => {
        if (Math.abs(px[i] - c[0]) <= tolerance && Math.abs(px[i + 1] - c[1]) <= tolerance &&
            Math.abs(px[i + 2] - c[2]) <= tolerance) {
          ++counts[k];
        }
      });
    }
    return counts;
  }, {base64: png.toString('base64'), colours, tolerance: kTolerance});
}

async function main() {
  const [report, screenshot] = process.argv.slice(2);
  if (!report || !screenshot) fail('usage: node check_view3d.cjs REPORT_HTML SCREENSHOT_PNG');
  const browser = await chromium.launch({
    executablePath: process.env.SONARBENCH_CHROMIUM || '/usr/bin/chromium',
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--no-first-run'],
  });
  const errors = [];
  try {
    const page = await browser.newPage({viewport: {width: 1280, height: 1000}});
    page.on('console', (m) => { if (m.type() === 'error') errors.push(`console: ${m.text()}`); });
    page.on('pageerror', (e) => errors.push(`exception: ${e.message}`));
    await page.goto(`file://${path.resolve(report)}`);
    await page.waitForFunction(() => window.sonarbenchView && window.sonarbenchView.drawn,
                               null, {timeout: 120000}).catch(() => {});
    const view = await page.evaluate(() => window.sonarbenchView);
    if (!view) fail(`${report}: the 3D view was not drawn; ${errors.join('; ') || 'no error'}`);
    const canvas = page.locator('#view3d canvas');
    const shown = view.classes.filter((c) => c.drawn > 0);
    fs.writeFileSync(screenshot, await canvas.screenshot());
    // Counted with the legend (drawn over the canvas, with a swatch of each colour) masked.
    const masked = {mask: [page.locator('.view3d-legend')], maskColor: '#1e1e1e'};
    const counts = await countColours(page, await canvas.screenshot(masked),
                                      shown.map((c) => c.colour));
    shown.forEach((c, k) => {
      console.log(`${c.name} (${c.colour}): ${c.drawn} cells, ${counts[k]} pixels`);
      if (counts[k] < kMinPixels) fail(`${c.name}: ${c.drawn} cells, but its colour is not seen`);
    });
    // Hiding the first class takes its colour off the canvas.
    const hidden = shown[0];
    await page.locator('.view3d-legend label', {hasText: hidden.name}).locator('input').uncheck();
    const [after] = await countColours(page, await canvas.screenshot(masked), [hidden.colour]);
    console.log(`${hidden.name} hidden: ${after} pixels`);
    if (after > counts[0] / 50) fail(`${hidden.name} hidden, yet ${after} pixels keep its colour`);
    if (errors.length) fail(errors.join('; '));
  } finally {
    await browser.close();
  }
}

main().catch((e) => fail(e.stack || String(e)));
