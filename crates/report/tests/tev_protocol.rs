//! The tev client against a small in-process server that records and decodes what a tev
//! instance would receive, including a server that hangs up in the middle of a render.

use std::io::Read;
use std::net::{TcpListener, TcpStream};
use std::sync::mpsc;
use std::thread;
use std::time::Duration;

use radiant_report::tev::{Layout, Packet, TILE_SIZE, TevClient, TevError, TevLiveView, Tile};

/// Reads length-prefixed packets until EOF or `limit` packets, then drops the socket.
fn read_packets(mut stream: TcpStream, limit: usize) -> Vec<Vec<u8>> {
    stream
        .set_read_timeout(Some(Duration::from_secs(20)))
        .unwrap();
    let mut packets = Vec::new();
    while packets.len() < limit {
        let mut len = [0u8; 4];
        if stream.read_exact(&mut len).is_err() {
            break;
        }
        let n = u32::from_le_bytes(len) as usize;
        assert!((5..64 << 20).contains(&n), "implausible packet length {n}");
        let mut packet = len.to_vec();
        packet.resize(n, 0);
        stream.read_exact(&mut packet[4..]).expect("whole packet");
        packets.push(packet);
    }
    packets
}

/// A one-connection server on a free loopback port; the thread returns what it read.
fn server(limit: usize) -> (String, thread::JoinHandle<Vec<Vec<u8>>>) {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap().to_string();
    let handle = thread::spawn(move || {
        let (stream, _) = listener.accept().unwrap();
        read_packets(stream, limit)
    });
    (addr, handle)
}

#[test]
fn packets_have_tevs_byte_layout() {
    let (addr, handle) = server(usize::MAX);
    let mut c = TevClient::connect(addr.as_str()).unwrap();
    c.create_image("img", 3, 2, &["R", "G"]).unwrap();
    c.close_image("img").unwrap();
    drop(c);
    let packets = handle.join().unwrap();
    // Written out by hand from tev's Ipc.cpp: u32 total length, type 4, grab focus,
    // "img\0", width 3, height 2, 2 channels, "R\0", "G\0".
    let mut create = vec![0u8; 4];
    create.push(4);
    create.push(1);
    create.extend_from_slice(b"img\0");
    create.extend_from_slice(&3i32.to_le_bytes());
    create.extend_from_slice(&2i32.to_le_bytes());
    create.extend_from_slice(&2i32.to_le_bytes());
    create.extend_from_slice(b"R\0G\0");
    let n = create.len() as u32;
    create[..4].copy_from_slice(&n.to_le_bytes());
    assert_eq!(packets[0], create);
    // CloseImage: length 9 = 4 + type + "img\0".
    assert_eq!(packets[1], [9, 0, 0, 0, 2, b'i', b'm', b'g', 0]);
}

#[test]
fn update_tile_layouts_decode_to_the_same_channels() {
    let (addr, handle) = server(usize::MAX);
    let mut c = TevClient::connect(addr.as_str()).unwrap();
    // 2×1 tile, channels R, G: planar R0 R1 G0 G1, interleaved R0 G0 R1 G1.
    let planar = [1.0f32, 2.0, 10.0, 20.0];
    let interleaved = [1.0f32, 10.0, 2.0, 20.0];
    for (data, layout) in [
        (&planar, Layout::Planar),
        (&interleaved, Layout::Interleaved),
    ] {
        let tile = Tile {
            x: 5,
            y: 7,
            width: 2,
            height: 1,
            channels: &["R", "G"],
            data,
            layout,
        };
        c.update_tile("live", &tile).unwrap();
    }
    drop(c);
    let packets = handle.join().unwrap();
    assert_eq!(packets.len(), 2);
    // The v3 header by hand: type 6, no focus grab, "live\0", 2 channels, names,
    // x y w h, then offsets and strides (i64): planar 0, 2 / 1, 1.
    let p = &packets[0];
    assert_eq!(p[4], 6);
    assert_eq!(p[5], 0);
    assert_eq!(&p[6..11], b"live\0");
    let header_end = 11 + 4 + 4 + 16;
    let i64_at = |k: usize| i64::from_le_bytes(p[header_end + 8 * k..][..8].try_into().unwrap());
    assert_eq!([i64_at(0), i64_at(1), i64_at(2), i64_at(3)], [0, 2, 1, 1]);
    assert_eq!(p.len(), header_end + 32 + 16);
    for p in &packets {
        let decoded = Packet::decode(p).unwrap();
        assert_eq!(
            decoded,
            Packet::UpdateImage {
                grab_focus: false,
                name: "live".into(),
                channels: vec!["R".into(), "G".into()],
                x: 5,
                y: 7,
                width: 2,
                height: 1,
                data: vec![vec![1.0, 2.0], vec![10.0, 20.0]],
            }
        );
    }
}

#[test]
fn update_rgb_covers_the_image_in_tiles() {
    let (w, h) = (300u32, 130u32);
    let pixels: Vec<[f32; 3]> = (0..w * h)
        .map(|i| [(i % w) as f32, (i / w) as f32, 0.5])
        .collect();
    let (addr, handle) = server(usize::MAX);
    let mut c = TevClient::connect(addr.as_str()).unwrap();
    c.create_image("frame", w, h, &["R", "G", "B"]).unwrap();
    c.update_rgb("frame", w, h, &pixels).unwrap();
    drop(c);
    let packets = handle.join().unwrap();
    // 3 × 2 tiles of at most 128²; together they cover every pixel exactly once.
    let tiles_x = w.div_ceil(TILE_SIZE);
    let tiles_y = h.div_ceil(TILE_SIZE);
    assert_eq!(packets.len() as u32, 1 + tiles_x * tiles_y);
    let mut seen = vec![0u8; (w * h) as usize];
    for p in &packets[1..] {
        let Packet::UpdateImage {
            x,
            y,
            width,
            height,
            data,
            channels,
            ..
        } = Packet::decode(p).unwrap()
        else {
            panic!("expected UpdateImage");
        };
        assert_eq!(channels, ["R", "G", "B"]);
        assert!(width as u32 <= TILE_SIZE && height as u32 <= TILE_SIZE);
        for ty in 0..height {
            for tx in 0..width {
                let (px, py) = (x + tx, y + ty);
                let k = (ty * width + tx) as usize;
                assert_eq!(data[0][k], px as f32);
                assert_eq!(data[1][k], py as f32);
                assert_eq!(data[2][k], 0.5);
                seen[(py as u32 * w + px as u32) as usize] += 1;
            }
        }
    }
    assert!(seen.iter().all(|&n| n == 1));
}

#[test]
fn other_packets_round_trip() {
    let packets = [
        Packet::OpenImage {
            grab_focus: true,
            path: "/tmp/a b.exr".into(),
            channel_selector: "R,G".into(),
        },
        Packet::ReloadImage {
            grab_focus: false,
            name: "x".into(),
        },
        Packet::CloseImage {
            name: "ünïcode".into(),
        },
        Packet::CreateImage {
            grab_focus: true,
            name: "n".into(),
            width: 4,
            height: 5,
            channels: vec!["Y".into()],
        },
    ];
    for p in &packets {
        let bytes = p.encode().unwrap();
        assert_eq!(
            u32::from_le_bytes(bytes[..4].try_into().unwrap()) as usize,
            bytes.len()
        );
        assert_eq!(&Packet::decode(&bytes).unwrap(), p);
        // Any truncation is detected.
        assert!(Packet::decode(&bytes[..bytes.len() - 1]).is_err());
    }
}

#[test]
fn bad_input_is_an_error_not_a_panic() {
    let (addr, handle) = server(usize::MAX);
    let mut c = TevClient::connect(addr.as_str()).unwrap();
    let err = c.create_image("a\0b", 1, 1, &["R"]).unwrap_err();
    assert!(matches!(err, TevError::InvalidString(_)), "{err}");
    assert!(matches!(
        c.create_image("a", 1, 1, &[]),
        Err(TevError::NoChannels)
    ));
    let tile = Tile {
        x: 0,
        y: 0,
        width: 2,
        height: 2,
        channels: &["R"],
        data: &[1.0; 3],
        layout: Layout::Planar,
    };
    let err = c.update_tile("a", &tile).unwrap_err();
    assert!(
        matches!(
            err,
            TevError::DataSize {
                expected: 4,
                got: 3
            }
        ),
        "{err}"
    );
    assert!(c.update_rgb("a", 2, 2, &[[0.0; 3]; 3]).is_err());
    drop(c);
    // Nothing invalid reached the wire.
    assert!(handle.join().unwrap().is_empty());
    assert!(Packet::decode(&[5, 0, 0, 0, 99]).is_err());
    assert!(Packet::decode(&[6, 0, 0, 0, 2, b'x']).is_err()); // no NUL
}

#[test]
fn connecting_to_nothing_fails_cleanly() {
    // Bind then drop a listener: the port is (almost surely) closed now.
    let addr = TcpListener::bind("127.0.0.1:0")
        .unwrap()
        .local_addr()
        .unwrap();
    let err = TevClient::connect(addr).unwrap_err();
    assert!(matches!(err, TevError::Io(_)), "{err}");
    let mut view = TevLiveView::start(addr, "render", 4, 4);
    assert!(!view.is_active());
    view.update(&[[1.0; 3]; 16]); // does nothing, does not panic
    assert!(matches!(view.failure(), Some(TevError::Io(_))));
}

#[test]
fn live_view_survives_a_server_that_hangs_up_mid_stream() {
    // The server reads CreateImage and two updates, then closes the connection.
    let (addr, handle) = server(3);
    let (w, h) = (64u32, 64u32);
    let frame = vec![[0.25f32; 3]; (w * h) as usize];
    let mut view = TevLiveView::start(addr.as_str(), "render", w, h);
    assert!(view.is_active());
    let (done_tx, done_rx) = mpsc::channel();
    let render = thread::spawn(move || {
        // A "render" that keeps pushing progress; it must run to the end regardless.
        let mut sent_after_failure = 0;
        for pass in 0..2000 {
            view.update(&frame);
            if !view.is_active() {
                sent_after_failure += 1;
            }
            if pass % 100 == 99 {
                thread::sleep(Duration::from_millis(1));
            }
        }
        done_tx.send(()).unwrap();
        (view, sent_after_failure)
    });
    let received = handle.join().unwrap();
    assert_eq!(received.len(), 3);
    assert!(matches!(
        Packet::decode(&received[0]).unwrap(),
        Packet::CreateImage { .. }
    ));
    assert!(matches!(
        Packet::decode(&received[1]).unwrap(),
        Packet::UpdateImage { .. }
    ));
    done_rx
        .recv_timeout(Duration::from_secs(60))
        .expect("render finished despite the viewer closing");
    let (view, passes_after) = render.join().unwrap();
    assert!(!view.is_active(), "the closed connection was noticed");
    assert!(passes_after > 0);
    let failure = view.failure().expect("failure remembered").to_string();
    assert!(failure.starts_with("tev connection:"), "{failure}");
}

#[test]
fn peer_open_notices_a_closed_viewer() {
    let listener = TcpListener::bind("127.0.0.1:0").unwrap();
    let addr = listener.local_addr().unwrap();
    let mut c = TevClient::connect(addr).unwrap();
    let (server_side, _) = listener.accept().unwrap();
    assert!(c.peer_open());
    drop(server_side);
    // The FIN arrives asynchronously; allow it a moment.
    let closed = (0..200).any(|_| {
        thread::sleep(Duration::from_millis(5));
        !c.peer_open()
    });
    assert!(closed);
}
