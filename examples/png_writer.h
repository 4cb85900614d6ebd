/* png_writer.h - an RGB picture in memory, a few drawing calls, and a PNG writer, for the examples.

   So that a run can be looked at without ParaView, and without any library beyond libc: every byte
   of the file is made here. The PNG (RGB, 8 bits a channel, no interlace, filter "None" on every
   row) holds one zlib stream (RFC 1950) of one deflate block (RFC 1951) with the fixed Huffman
   codes; the compressor looks for repeats at two distances only, the pixel to the left and the pixel
   above, which is what a picture of flat colours is made of (a 739 x 524 frame of the demo takes
   about 140 kB instead of 1.16 MB). CRC-32 (PNG chunks) and Adler-32 (zlib) are computed here too.

   Every function is static inline, so a file may use a few of them without warnings. Pixels are
   (x, y) from the top-left corner, y downwards; a colour is three bytes r, g, b. */
#ifndef PNG_WRITER_H
#define PNG_WRITER_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

typedef struct rgb_image {
    int width, height;
    unsigned char *pixels; /* width * height * 3 bytes, row after row from the top */
} rgb_image;

/* Allocates a width x height picture, black. 0 when out of memory. */
static inline int rgb_image_create(rgb_image *image, int width, int height) {
    image->width = width;
    image->height = height;
    image->pixels = (unsigned char *)calloc((size_t)width * (size_t)height, 3);
    return image->pixels != NULL;
}

static inline void rgb_image_free(rgb_image *image) {
    free(image->pixels);
    image->pixels = NULL;
}

/* Mixes `colour` into pixel (x, y) with weight `cover` in [0, 1]; pixels off the picture are skipped,
   so callers need not clip. */
static inline void rgb_image_blend(rgb_image *image, int x, int y, const unsigned char colour[3], double cover) {
    unsigned char *p;
    int c;
    if (x < 0 || y < 0 || x >= image->width || y >= image->height || cover <= 0) return;
    if (cover > 1) cover = 1;
    p = image->pixels + 3 * ((size_t)y * (size_t)image->width + (size_t)x);
    for (c = 0; c < 3; ++c) p[c] = (unsigned char)(p[c] + cover * (colour[c] - p[c]) + 0.5);
}

/* Fills the pixels x0 <= x < x1, y0 <= y < y1. */
static inline void rgb_image_fill_rect(rgb_image *image, int x0, int y0, int x1, int y1,
                                       const unsigned char colour[3]) {
    int x, y;
    for (y = y0; y < y1; ++y)
        for (x = x0; x < x1; ++x) rgb_image_blend(image, x, y, colour, 1);
}

/* Fills the disc of centre (cx, cy) and radius r (pixels, any real values); the edge pixels are
   mixed by how far inside their centre lies, so small discs stay round. */
static inline void rgb_image_fill_disc(rgb_image *image, double cx, double cy, double r,
                                       const unsigned char colour[3]) {
    int x, y;
    for (y = (int)floor(cy - r - 1); y <= (int)ceil(cy + r + 1); ++y)
        for (x = (int)floor(cx - r - 1); x <= (int)ceil(cx + r + 1); ++x) {
            double d = sqrt((x + 0.5 - cx) * (x + 0.5 - cx) + (y + 0.5 - cy) * (y + 0.5 - cy));
            rgb_image_blend(image, x, y, colour, r - d + 0.5);
        }
}

/* Writes `text` with its top-left corner at (x, y) in a 3 x 5 pixel font, each font pixel a
   scale x scale square. Knows the digits, '.', '-', '=', ':', 't' and 's' (enough for a time
   label); anything else is a blank. */
static inline void rgb_image_text(rgb_image *image, int x, int y, int scale, const char *text,
                                  const unsigned char colour[3]) {
    /* one glyph = 5 rows of 3 bits, in octal one digit a row from the top; 4 is the left pixel */
    static const char glyph_chars[] = "0123456789.-=:ts";
    static const unsigned short glyphs[] = {
        075557, 026227, 071747, 071717, 055711, 074717, 074757, 071111, 075757, 075717, /* 0-9 */
        000002, 000700, 007070, 002020, 027223, 007637};                              /* . - = : t s */
    for (; *text; ++text, x += 4 * scale) {
        int g, row, column;
        for (g = 0; glyph_chars[g] && glyph_chars[g] != *text; ++g) {}
        if (!glyph_chars[g]) continue;
        for (row = 0; row < 5; ++row)
            for (column = 0; column < 3; ++column)
                if ((glyphs[g] >> (3 * (4 - row) + (2 - column))) & 1)
                    rgb_image_fill_rect(image, x + column * scale, y + row * scale, x + (column + 1) * scale,
                                        y + (row + 1) * scale, colour);
    }
}

/* ---- the PNG file ---- */

/* Bits go into bytes from the least significant end (RFC 1951 §3.1.1). */
typedef struct png__bits {
    unsigned char *out;
    size_t length;         /* whole bytes written */
    unsigned long pending; /* bits not yet a whole byte (fewer than 8 between calls) */
    int pending_count;
} png__bits;

static inline void png__put_bits(png__bits *bits, unsigned value, int count) {
    bits->pending |= (unsigned long)value << bits->pending_count;
    bits->pending_count += count;
    for (; bits->pending_count >= 8; bits->pending_count -= 8, bits->pending >>= 8)
        bits->out[bits->length++] = (unsigned char)(bits->pending & 0xff);
}

/* Huffman codes are sent from their most significant bit, the reverse of the other fields. */
static inline void png__put_code(png__bits *bits, unsigned code, int count) {
    unsigned reversed = 0;
    int i;
    for (i = 0; i < count; ++i) reversed |= ((code >> i) & 1u) << (count - 1 - i);
    png__put_bits(bits, reversed, count);
}

/* A literal byte (0-255), the end of the block (256) or a length code (257-285) in the fixed
   literal/length code of RFC 1951 §3.2.6. */
static inline void png__put_symbol(png__bits *bits, unsigned symbol) {
    if (symbol < 144) png__put_code(bits, 0x30 + symbol, 8);
    else if (symbol < 256) png__put_code(bits, 0x190 + symbol - 144, 9);
    else if (symbol < 280) png__put_code(bits, symbol - 256, 7);
    else png__put_code(bits, 0xc0 + symbol - 280, 8);
}

/* "Copy `length` (3-258) bytes from `distance` (1-32768) back": a length code with its extra bits,
   then a distance code (fixed: 5 bits) with its extra bits (RFC 1951 §3.2.5). */
static inline void png__put_match(png__bits *bits, unsigned length, unsigned distance) {
    static const unsigned short length_base[29] = {3,  4,  5,  6,  7,  8,  9,  10, 11,  13,  15,  17,  19,  23, 27,
                                                   31, 35, 43, 51, 59, 67, 83, 99, 115, 131, 163, 195, 227, 258};
    static const unsigned short distance_base[30] = {1,   2,   3,   4,   5,   7,    9,    13,   17,   25,
                                                     33,  49,  65,  97,  129, 193,  257,  385,  513,  769,
                                                     1025, 1537, 2049, 3073, 4097, 6145, 8193, 12289, 16385, 24577};
    int code = 28;
    while (length_base[code] > length) --code;
    png__put_symbol(bits, 257u + (unsigned)code);
    /* extra bits: none for the first 8 lengths and for 258, then one more every 4 codes */
    png__put_bits(bits, length - length_base[code], code < 8 || code == 28 ? 0 : (code - 4) / 4);
    for (code = 29; distance_base[code] > distance; --code) {}
    png__put_code(bits, (unsigned)code, 5);
    png__put_bits(bits, distance - distance_base[code], code < 4 ? 0 : (code - 2) / 2);
}

/* Deflates `size` bytes into `bits` as one final fixed-Huffman block. `row` is the distance to the
   same byte one row up. Greedy: at each byte the longer repeat of the pixel to the left (3 back) or
   of the row above, if it is 3 bytes or more, else a literal. */
static inline void png__deflate(png__bits *bits, const unsigned char *data, size_t size, size_t row) {
    const size_t distances[2] = {3, row};
    size_t at = 0;
    png__put_bits(bits, 1, 1); /* BFINAL: the only block */
    png__put_bits(bits, 1, 2); /* BTYPE 01: fixed Huffman codes */
    while (at < size) {
        size_t best_length = 0, best_distance = 0, most = size - at < 258 ? size - at : 258;
        int k;
        for (k = 0; k < 2; ++k) {
            size_t d = distances[k], n = 0;
            if (d > at || d > 32768) continue;
            while (n < most && data[at + n] == data[at + n - d]) ++n;
            if (n > best_length) best_length = n, best_distance = d;
        }
        if (best_length >= 3) {
            png__put_match(bits, (unsigned)best_length, (unsigned)best_distance);
            at += best_length;
        } else
            png__put_symbol(bits, data[at++]);
    }
    png__put_symbol(bits, 256); /* end of block */
    if (bits->pending_count > 0) png__put_bits(bits, 0, 8 - bits->pending_count); /* to a byte boundary */
}

/* CRC-32 of PNG (ISO 3309: polynomial 0xedb88320 bit-reversed, register starting at all ones,
   inverted at the end); `crc` is the value so far (0 to start), so a chunk is summed in parts. */
static inline unsigned long png__crc32(unsigned long crc, const unsigned char *data, size_t size) {
    size_t i;
    int bit;
    crc = ~crc & 0xffffffffUL;
    for (i = 0; i < size; ++i) {
        crc ^= data[i];
        for (bit = 0; bit < 8; ++bit) crc = crc & 1 ? (crc >> 1) ^ 0xedb88320UL : crc >> 1;
    }
    return ~crc & 0xffffffffUL;
}

/* Adler-32 of zlib: two sums modulo 65521; reduced every 5552 bytes, the longest run after which
   the second sum still fits 32 bits. */
static inline unsigned long png__adler32(const unsigned char *data, size_t size) {
    unsigned long a = 1, b = 0;
    size_t i = 0;
    while (i < size) {
        size_t end = size - i > 5552 ? i + 5552 : size;
        for (; i < end; ++i) b += a += data[i];
        a %= 65521;
        b %= 65521;
    }
    return (b << 16) | a;
}

static inline void png__put32(unsigned char *at, unsigned long value) { /* big-endian, as PNG and zlib want */
    at[0] = (unsigned char)(value >> 24 & 0xff);
    at[1] = (unsigned char)(value >> 16 & 0xff);
    at[2] = (unsigned char)(value >> 8 & 0xff);
    at[3] = (unsigned char)(value & 0xff);
}

/* One chunk: length, type, data, and the CRC of type and data. 0 on a write error. */
static inline int png__write_chunk(FILE *file, const char *type, const unsigned char *data, size_t size) {
    unsigned char head[8], tail[4];
    png__put32(head, (unsigned long)size);
    head[4] = (unsigned char)type[0], head[5] = (unsigned char)type[1];
    head[6] = (unsigned char)type[2], head[7] = (unsigned char)type[3];
    png__put32(tail, png__crc32(png__crc32(0, head + 4, 4), data, size));
    return fwrite(head, 1, 8, file) == 8 && fwrite(data, 1, size, file) == size && fwrite(tail, 1, 4, file) == 4;
}

/* Writes the picture to `path` as a PNG. 0 on success, -1 when out of memory or the file cannot be
   written. */
static inline int rgb_image_write_png(const rgb_image *image, const char *path) {
    static const unsigned char signature[8] = {137, 'P', 'N', 'G', '\r', '\n', 26, '\n'};
    const size_t row = 1 + 3 * (size_t)image->width, raw_size = row * (size_t)image->height;
    unsigned char header[13], *raw = (unsigned char *)malloc(raw_size);
    /* room for the worst case: a literal takes at most 9 bits, a match of n bytes at most 7 + 5 + 13
       (n <= 10, no extra length bits) or 8 + 5 + 5 + 13 (n > 10): under 9 n. So the stream is at
       most 9/8 of raw_size and its 6 bytes of zlib header and checksum */
    png__bits bits = {NULL, 0, 0, 0};
    FILE *file = NULL;
    int y, ok = 0;
    bits.out = (unsigned char *)malloc(raw_size + raw_size / 4 + 16);
    if (raw && bits.out) {
        for (y = 0; y < image->height; ++y) { /* each row: filter type 0, then the pixels */
            raw[y * row] = 0;
            memcpy(raw + y * row + 1, image->pixels + (size_t)y * (row - 1), row - 1);
        }
        bits.out[bits.length++] = 0x78; /* zlib: deflate, 32 kB window; */
        bits.out[bits.length++] = 0x01; /* check bits make 0x7801 a multiple of 31 */
        png__deflate(&bits, raw, raw_size, row);
        png__put32(bits.out + bits.length, png__adler32(raw, raw_size));
        bits.length += 4;
        png__put32(header, (unsigned long)image->width);
        png__put32(header + 4, (unsigned long)image->height);
        header[8] = 8;  /* bits per channel */
        header[9] = 2;  /* colour type: RGB */
        header[10] = 0; /* compression: deflate */
        header[11] = 0; /* filtering: adaptive, per row */
        header[12] = 0; /* no interlace */
        file = fopen(path, "wb");
        ok = file && fwrite(signature, 1, 8, file) == 8 && png__write_chunk(file, "IHDR", header, 13) &&
             png__write_chunk(file, "IDAT", bits.out, bits.length) && png__write_chunk(file, "IEND", header, 0);
        if (file && fclose(file) != 0) ok = 0;
    }
    free(raw);
    free(bits.out);
    return ok ? 0 : -1;
}

#endif /* PNG_WRITER_H */
