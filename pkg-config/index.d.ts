// Types of the robocal npm package (node entry). Functions come from the
// wasm-bindgen declarations; the JSON shapes they exchange are below.
export * from './node/robocal.js';

/** What `image_info` returns (and `ImagePreview.info_json` holds), as JSON. */
export interface ImageInfo {
  /** Container format, lower case. */
  format: 'png' | 'jpeg' | 'tiff' | 'bmp' | 'pnm' | 'gif';
  /** Upper-case display name, e.g. "PNG". */
  format_name: string;
  width: number;
  height: number;
  /** 1 grey, 2 grey+alpha, 3 RGB, 4 RGBA. */
  channels: number;
  bits_per_channel: number;
}
