// SPDX-License-Identifier: MIT
// Headless chromium for the browser tests and the shader benchmark, through puppeteer-core: WebGL2
// on SwiftShader (the same software GPU on every machine, so images and frame times compare
// between runs), no background traffic, and PROFILE as its profile folder (the caller's to remove).
export function launchChromium(puppeteer, executablePath, profile) {
  return puppeteer.launch({
    executablePath,
    headless: true,
    args: ['--no-sandbox', '--use-angle=swiftshader', '--enable-unsafe-swiftshader',
           '--disable-background-networking', '--disable-component-update', '--disable-sync',
           '--no-first-run', `--user-data-dir=${profile}`],
  });
}
