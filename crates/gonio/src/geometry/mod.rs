pub mod mesh_io;
