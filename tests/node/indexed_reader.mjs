// SPDX-License-Identifier: Apache-2.0
// The official reader's indexed access to a file on disk (@mcap/core's McapIndexedReader over a
// file handle), shared by the scripts here. Returns { reader, close }.
import { open } from "node:fs/promises";
import { McapIndexedReader } from "@mcap/core";

export async function openIndexed(path, decompressHandlers) {
  const handle = await open(path, "r");
  const size = BigInt((await handle.stat()).size);
  const readable = {
    size: async () => size,
    read: async (offset, length) => {
      const b = new Uint8Array(Number(length));
      const { bytesRead } = await handle.read(b, 0, b.length, Number(offset));
      if (bytesRead !== b.length) throw new Error(`short read at ${offset}`);
      return b;
    },
  };
  const reader = await McapIndexedReader.Initialize({ readable, decompressHandlers });
  return { reader, close: () => handle.close() };
}
