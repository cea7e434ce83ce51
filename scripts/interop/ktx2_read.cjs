// Reads a KTX2 file with ktx-parse (the KTX2 reader three.js and
// glTF-Transform use) and prints what it found as JSON, for
// scripts/interop/ktx2_parse.py.
const { read } = require('ktx-parse');
const fs = require('fs');
const c = read(new Uint8Array(fs.readFileSync(process.argv[2])));
const d = c.dataFormatDescriptor[0];
console.log(JSON.stringify({
  vkFormat: c.vkFormat, typeSize: c.typeSize, width: c.pixelWidth, height: c.pixelHeight,
  levels: c.levels.length, layers: c.layerCount, faces: c.faceCount,
  scheme: c.supercompressionScheme, model: d.colorModel,
  transfer: d.transferFunction, block: d.texelBlockDimension, bytesPlane0: d.bytesPlane[0],
  uncompressed: c.levels.map(l => l.uncompressedByteLength),
  // Each sample: bit offset, bit length - 1, channel id with qualifiers.
  samples: d.samples.map(s => [s.bitOffset, s.bitLength, s.channelType]),
  flags: d.flags,
  stored: c.levels.map(l => l.levelData.length),
}));
