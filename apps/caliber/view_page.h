#pragma once
// The viewer page of `caliber view`, generated at build time (viewer/embed.py): the HTML template
// around the recorded data, and the viewer's script with three.js bundled by esbuild.

#include <string_view>

namespace caliber::cli {

/// False when the build found no viewer/node_modules (three.js and esbuild from npm; see
/// scripts/setup.sh): `caliber view` then refuses with a message saying so.
extern const bool kViewerBuilt;
/// The page is kPageHead, the data (JSON), kPageMiddle, kViewerScript, kPageTail.
extern const std::string_view kPageHead;
extern const std::string_view kPageMiddle;
extern const std::string_view kPageTail;
extern const std::string_view kViewerScript;

}  // namespace caliber::cli
