use super::*;
use crate::rng::Rng;

/// OpenCV 4.14's marker counts, marker sizes and maxCorrectionBits
/// (`cv2.aruco.getPredefinedDictionary(d)`: `bytesList.shape[0]`,
/// `markerSize`, `maxCorrectionBits`), written out independently of the
/// generated file.
const OPENCV: [(Dictionary, usize, usize, u32); 22] = [
    (Dictionary::DICT_4X4_50, 50, 4, 1),
    (Dictionary::DICT_4X4_100, 100, 4, 1),
    (Dictionary::DICT_4X4_250, 250, 4, 1),
    (Dictionary::DICT_4X4_1000, 1000, 4, 0),
    (Dictionary::DICT_5X5_50, 50, 5, 3),
    (Dictionary::DICT_5X5_100, 100, 5, 3),
    (Dictionary::DICT_5X5_250, 250, 5, 2),
    (Dictionary::DICT_5X5_1000, 1000, 5, 2),
    (Dictionary::DICT_6X6_50, 50, 6, 6),
    (Dictionary::DICT_6X6_100, 100, 6, 5),
    (Dictionary::DICT_6X6_250, 250, 6, 5),
    (Dictionary::DICT_6X6_1000, 1000, 6, 4),
    (Dictionary::DICT_7X7_50, 50, 7, 9),
    (Dictionary::DICT_7X7_100, 100, 7, 8),
    (Dictionary::DICT_7X7_250, 250, 7, 8),
    (Dictionary::DICT_7X7_1000, 1000, 7, 6),
    (Dictionary::DICT_ARUCO_ORIGINAL, 1024, 5, 1),
    (Dictionary::DICT_APRILTAG_16h5, 30, 4, 2),
    (Dictionary::DICT_APRILTAG_25h9, 35, 5, 4),
    (Dictionary::DICT_APRILTAG_36h10, 2320, 6, 4),
    (Dictionary::DICT_APRILTAG_36h11, 587, 6, 5),
    (Dictionary::DICT_ARUCO_MIP_36h12, 250, 6, 5),
];

#[test]
fn every_dictionary_has_opencvs_counts_sizes_and_correction() {
    for (d, count, size, correction) in OPENCV {
        assert_eq!(d.len(), count, "{} markers", d.name());
        assert_eq!(d.marker_bits(), size, "{} bits per side", d.name());
        assert_eq!(
            d.max_correction_bits(),
            correction,
            "{} correction",
            d.name()
        );
        assert_eq!(Dictionary::from_name(d.name()).unwrap(), d);
    }
}

#[test]
fn apriltag_36h11_is_the_apriltag_projects_code() {
    // AprilTag's tag36h11 code 0 is 0xd5d628584 with the first bit the one
    // OpenCV draws at the bottom right: OpenCV's row-major bits reversed.
    let code = Dictionary::DICT_APRILTAG_36h11.code(0).unwrap();
    assert_eq!(code.reverse_bits() >> (64 - 36), 0xd5d628584);
    // The small dictionaries are the first markers of the 1000 ones.
    for id in 0..250 {
        assert_eq!(
            Dictionary::DICT_7X7_250.code(id),
            Dictionary::DICT_7X7_1000.code(id)
        );
    }
}

#[test]
fn unknown_dictionary_lists_the_known_ones() {
    let e = Dictionary::from_name("DICT_8X8_50")
        .unwrap_err()
        .to_string();
    assert!(e.contains("unknown marker dictionary 'DICT_8X8_50'"), "{e}");
    assert!(e.contains("DICT_4X4_50, DICT_4X4_100"), "{e}");
    assert!(e.contains("DICT_ARUCO_MIP_36h12"), "{e}");
    assert_eq!(
        Dictionary::from_name("dict_apriltag_36H11").unwrap(),
        Dictionary::DICT_APRILTAG_36h11
    );
}

#[test]
fn rotation_four_times_is_identity_and_matches_a_hand_turned_grid() {
    // 2 x 2: [a b; c d] turned clockwise is [c a; d b].
    assert_eq!(rotate_clockwise(0b1000, 2), 0b0100);
    assert_eq!(rotate_clockwise(0b0001, 2), 0b0010);
    let c = Dictionary::DICT_7X7_50.code(3).unwrap();
    let mut r = c;
    for _ in 0..4 {
        r = rotate_clockwise(r, 7);
    }
    assert_eq!(r, c);
}

/// Smallest Hamming distance between a marker and any other marker in any
/// rotation, or itself turned (what the correction can rely on).
fn min_distance(d: Dictionary) -> u32 {
    let n = d.marker_bits();
    let rotations: Vec<[u64; 4]> = (0..d.len())
        .map(|id| {
            let c = d.code(id).unwrap();
            let r1 = rotate_clockwise(c, n);
            let r2 = rotate_clockwise(r1, n);
            [c, r1, r2, rotate_clockwise(r2, n)]
        })
        .collect();
    let mut best = u32::MAX;
    for (i, ri) in rotations.iter().enumerate() {
        for k in 1..4 {
            best = best.min((ri[0] ^ ri[k]).count_ones());
        }
        for rj in &rotations[i + 1..] {
            for r in rj {
                best = best.min((ri[0] ^ r).count_ones());
            }
        }
    }
    best
}

#[test]
fn every_marker_decodes_in_every_rotation_with_the_documented_bit_errors() {
    // OpenCV's maxCorrectionBits is honoured by every table but
    // DICT_ARUCO_ORIGINAL, whose markers include pairs one bit apart
    // across rotations (marker 255 turned three times is marker 1022
    // turned once with one bit changed): there the correction that is
    // safe is floor((d_min - 1) / 2) = 0 and a read one bit off can be
    // another marker. The decoder keeps OpenCV's limit (what OpenCV
    // does); this test flips as many bits as the table guarantees.
    let mut rng = Rng::new(18);
    for d in Dictionary::ALL {
        let n = d.marker_bits();
        let safe = (min_distance(d).saturating_sub(1)) / 2;
        let max = d.max_correction_bits().min(safe);
        if d != Dictionary::DICT_ARUCO_ORIGINAL {
            assert_eq!(
                max,
                d.max_correction_bits(),
                "{} is not safe to its stated correction",
                d.name()
            );
        } else {
            assert_eq!(max, 0, "ARUCO_ORIGINAL's safe correction");
        }
        for id in 0..d.len() {
            let code = d.code(id).unwrap();
            let mut turned = code;
            for rotation in 0..4 {
                // Flip exactly `max` distinct bits at random.
                let mut read = turned;
                let mut flipped = 0;
                while flipped < max {
                    let bit = 1u64 << rng.below(n * n);
                    if (read ^ turned) & bit == 0 {
                        read ^= bit;
                        flipped += 1;
                    }
                }
                let got = d.decode(read, d.max_correction_bits());
                let what = format!(
                    "{} marker {id} turned {rotation} times with {max} bit errors",
                    d.name()
                );
                let got = got.unwrap_or_else(|| panic!("{what}: not decoded"));
                assert_eq!((got.id, got.bit_errors), (id, max), "{what}");
                // A marker symmetric under a half turn (ARUCO_ORIGINAL's
                // 1023) reads the same at two rotations: either is right.
                let mut at = code;
                for _ in 0..got.rotation {
                    at = rotate_clockwise(at, n);
                }
                assert_eq!(at, turned, "{what}: rotation {}", got.rotation);
                turned = rotate_clockwise(turned, n);
            }
        }
    }
}

#[test]
fn one_bit_past_the_limit_is_not_accepted_as_that_marker() {
    let d = Dictionary::DICT_5X5_100;
    let code = d.code(7).unwrap();
    let read = code ^ 0b1111; // 4 errors, the limit is 3
    assert!(d.decode(read, 3).map_or(true, |m| m.id != 7));
}
